#include "engine/edge_grid.h"

#include <algorithm>
#include <cmath>
#include <glm/common.hpp>
#include <glm/vec3.hpp>
#include <limits>

namespace dpc {

EdgeGrid::EdgeGrid(const std::vector<DiffractionEdge>& edges, float reach)
    : step_(0.25f * reach), cell_(1.3f * reach), mark_(edges.size(), 0) {
  for (uint32_t i = 0; i < uint32_t(edges.size()); ++i)
    forSamples(edges[i], [&](const glm::ivec3& c) {
      std::vector<uint32_t>& list = cells_[key(c)];
      if (list.empty() || list.back() != i) list.push_back(i);
    });
}

std::vector<uint32_t> EdgeGrid::near(const DiffractionEdge& e) {
  std::vector<uint32_t> out;
  ++query_;
  glm::ivec3 last(std::numeric_limits<int>::min());
  forSamples(e, [&](const glm::ivec3& c) {
    if (c == last) return;  // consecutive samples in one cell
    last = c;
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const auto it = cells_.find(key(c + glm::ivec3(dx, dy, dz)));
          if (it == cells_.end()) continue;
          for (uint32_t i : it->second)
            if (mark_[i] != query_) {
              mark_[i] = query_;
              out.push_back(i);
            }
        }
  });
  return out;
}

template <class F>
void EdgeGrid::forSamples(const DiffractionEdge& e, F&& visit) const {
  const int n = int(std::ceil(e.length / step_));
  for (int k = 0; k <= n; ++k) {
    const glm::vec3 p = e.a + (e.length * float(k) / float(std::max(n, 1))) * e.direction;
    visit(glm::ivec3(glm::floor(p / cell_)));
  }
}

uint64_t EdgeGrid::key(const glm::ivec3& c) {
  auto part = [](int v) { return uint64_t(uint32_t(v + (1 << 20)) & 0x1fffffu); };
  return part(c.x) | (part(c.y) << 21) | (part(c.z) << 42);
}

}  // namespace dpc
