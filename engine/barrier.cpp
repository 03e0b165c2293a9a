#include "engine/barrier.h"

#include <algorithm>
#include <cmath>

namespace dpc {

double multipleEdgeFactor(double lambda, double span) {
  const double r = 5.0 * lambda / std::max(span, 1e-6);
  return (1.0 + r * r) / (1.0 / 3.0 + r * r);
}

double screenGain(double lambda, double z, double span, int edges) {
  constexpr double kC2 = 40.0;
  const double c3 = edges >= 2 ? multipleEdgeFactor(lambda, span) : 1.0;
  return 1.0 / (3.0 + kC2 / lambda * c3 * std::max(z, 0.0));
}

double grazingAmplitude(double excess, double span, double lambda) {
  if (excess < 0.0) return 1.0;
  const double v = -2.0 * std::sqrt(excess / lambda);
  if (v <= -0.78) return 1.0;
  const double j = 6.9 + 20.0 * std::log10(std::sqrt((v - 0.1) * (v - 0.1) + 1.0) + v - 0.1);
  const double weight = 0.5 * (multipleEdgeFactor(lambda, span) - 1.0);
  return std::pow(10.0, -weight * j / 20.0);
}

}  // namespace dpc
