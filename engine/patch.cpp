#include "engine/patch.h"

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>

namespace dpc {

namespace {
uint16_t clampCount(double x) {
  if (!(x >= 1.0)) return 1;  // also NaN
  return uint16_t(std::min(65535.0, std::ceil(x)));
}
}  // namespace

TrianglePatching TrianglePatching::build(const glm::vec3& p0, const glm::vec3& p1,
                                         const glm::vec3& p2, float lambda) {
  const std::array<glm::dvec3, 3> p = {glm::dvec3(p0), glm::dvec3(p1), glm::dvec3(p2)};
  // Edge opposite vertex i joins the other two vertices.
  std::array<double, 3> edge{};
  for (int i = 0; i < 3; ++i) edge[i] = glm::length(p[(i + 2) % 3] - p[(i + 1) % 3]);
  const double twiceArea = glm::length(glm::cross(p[1] - p[0], p[2] - p[0]));
  TrianglePatching t;
  // The longest altitude 2A/e_i belongs to the shortest opposite edge.
  int k = 0;
  for (int i = 1; i < 3; ++i)
    if (edge[i] < edge[k]) k = i;
  t.keyVertex = uint8_t(k);
  if (!(twiceArea > 0.0) || !(edge[k] > 0.0)) return t;
  const double hk = twiceArea / edge[k];
  t.rows = clampCount(hk / lambda);
  t.widestColumns = clampCount(edge[k] / lambda);
  return t;
}

uint32_t TrianglePatching::columnsInRow(uint32_t zeta) const {
  const uint32_t n = rows;
  if (zeta >= n) return 1;
  // ceil((N_zeta - zeta) / N_zeta * N_xi), in integers: ceil(a*b/n).
  const uint64_t num = uint64_t(n - zeta) * widestColumns;
  return uint32_t(std::max<uint64_t>(1, (num + n - 1) / n));
}

uint32_t TrianglePatching::patchCount() const {
  uint32_t c = 0;
  for (uint32_t z = 0; z < rows; ++z) c += columnsInRow(z);
  return c;
}

std::array<uint32_t, 2> TrianglePatching::patchOf(const std::array<float, 3>& gamma) const {
  const float gk = std::clamp(gamma[keyVertex], 0.f, 1.f);
  const float ga = std::clamp(gamma[(keyVertex + 1) % 3], 0.f, 1.f);
  const uint32_t zeta = std::min<uint32_t>(uint32_t(gk * float(rows)), rows - 1u);
  const uint32_t cols = columnsInRow(zeta);
  const float width = 1.f - gk;
  const float s = width > 0.f ? std::clamp(ga / width, 0.f, 1.f) : 0.f;
  const uint32_t xi = std::min<uint32_t>(uint32_t(s * float(cols)), cols - 1u);
  return {zeta, xi};
}

}  // namespace dpc
