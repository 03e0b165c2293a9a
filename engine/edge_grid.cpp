#include "engine/edge_grid.h"

#include <algorithm>
#include <cmath>
#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include <limits>
#include <utility>

#include "engine/channel_path.h"
#include "engine/edge_path.h"

namespace dpc {

EdgeGrid::EdgeGrid(const std::vector<DiffractionEdge>& edges, float reach)
    : step_(0.25f * std::max(reach, 1e-3f)),
      cell_(1.3f * std::max(reach, 1e-3f)),
      mark_(edges.size(), 0) {
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

std::vector<uint32_t> parallelNeighbours(const std::vector<DiffractionEdge>& edges, uint32_t i,
                                         uint32_t other, float reach, size_t count,
                                         const std::vector<uint32_t>& candidates) {
  return parallelNeighbours(edges, edges[i], i, other, reach, count, candidates);
}

std::vector<uint32_t> parallelNeighbours(const std::vector<DiffractionEdge>& edges,
                                         const DiffractionEdge& e, uint32_t i, uint32_t other,
                                         float reach, size_t count,
                                         const std::vector<uint32_t>& candidates) {
  std::vector<std::pair<float, uint32_t>> found;
  for (uint32_t j : candidates) {
    const DiffractionEdge& c = edges[j];
    if (j == i || j == other || std::abs(glm::dot(c.direction, e.direction)) < kParallelEdges)
      continue;
    const float d = glm::length(acrossTo(e, c));
    const float ta = glm::dot(c.a - e.a, e.direction), tb = glm::dot(c.b - e.a, e.direction);
    if (d > 1e-4f && d <= reach && std::max(ta, tb) > 0.f && std::min(ta, tb) < e.length)
      found.push_back({d, j});
  }
  std::sort(found.begin(), found.end());
  if (found.size() > count) found.resize(count);
  std::vector<uint32_t> out;
  for (const auto& [d, j] : found) out.push_back(j);
  return out;
}

uint64_t EdgeGrid::key(const glm::ivec3& c) {
  auto part = [](int v) { return uint64_t(uint32_t(v + (1 << 20)) & 0x1fffffu); };
  return part(c.x) | (part(c.y) << 21) | (part(c.z) << 42);
}

}  // namespace dpc
