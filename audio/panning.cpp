// Constant-power stereo pan law (see panning.h).
#include "audio/panning.h"

#include <cmath>
#include <numbers>

namespace dpc::audio {

void stereoGains(const float dir[3], float* left, float* right) {
  const double x = std::fabs(double(dir[0])), y = double(dir[1]);
  double p = 0.5;  // centre
  if (std::isfinite(x) && std::isfinite(y) && (x > 0 || y != 0)) {
    const double phi = std::atan2(y, x);  // [-pi/2, pi/2], + = left
    p = phi / std::numbers::pi + 0.5;     // [0, 1]
  }
  const double a = p * (std::numbers::pi / 2);
  *left = float(std::sin(a));
  *right = float(std::cos(a));
}

}  // namespace dpc::audio
