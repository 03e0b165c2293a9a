#include "synthesis/spatial_directions.h"

#include <array>
#include <cmath>
#include <numbers>

#include "common/sphere_quadrature.h"

namespace dpc {

std::vector<glm::vec3> defaultSpatialDirections() {
  std::vector<glm::vec3> d;
  for (int i = 0; i < 6; ++i) {
    const float az = float(i) * std::numbers::pi_v<float> / 3.f;  // 0 = ahead, + = left
    d.push_back({std::cos(az), std::sin(az), 0.f});
  }
  d.push_back({0.f, 0.f, 1.f});
  const float el = -40.f * std::numbers::pi_v<float> / 180.f;
  d.push_back({std::cos(el), 0.f, std::sin(el)});
  return d;
}

std::vector<glm::vec3> uniformSpatialDirections(int count) {
  std::vector<glm::vec3> d;
  for (int i = 0; i < count; ++i) {
    const std::array<double, 3> p = fibonacciPoint(i, count);
    d.push_back({float(p[0]), float(p[1]), float(p[2])});
  }
  return d;
}

}  // namespace dpc
