#include "engine/sphere_bvh.h"

#include <algorithm>
#include <cmath>
#include <glm/common.hpp>

namespace dpc {

void SphereBvh::build(std::span<const glm::vec4> spheres) {
  nodes_.clear();
  order_.resize(spheres.size());
  for (uint32_t i = 0; i < order_.size(); ++i) order_[i] = i;
  if (spheres.empty()) return;
  nodes_.reserve(2 * spheres.size());
  buildNode(spheres, 0, uint32_t(spheres.size()));
}

uint32_t SphereBvh::buildNode(std::span<const glm::vec4> spheres, uint32_t first,
                              uint32_t count) {
  const uint32_t index = uint32_t(nodes_.size());
  nodes_.emplace_back();
  Node n;
  n.lo = glm::vec3(INFINITY);
  n.hi = glm::vec3(-INFINITY);
  for (uint32_t i = first; i < first + count; ++i) {
    const glm::vec4& s = spheres[order_[i]];
    n.lo = glm::min(n.lo, glm::vec3(s) - s.w);
    n.hi = glm::max(n.hi, glm::vec3(s) + s.w);
  }
  if (count <= kLeafSize) {
    n.first = first;
    n.count = count;
    nodes_[index] = n;
    return index;
  }
  const glm::vec3 extent = n.hi - n.lo;
  const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
  const uint32_t half = count / 2;
  std::nth_element(order_.begin() + first, order_.begin() + first + half,
                   order_.begin() + first + count, [&](uint32_t a, uint32_t b) {
                     return spheres[a][axis] < spheres[b][axis] ||
                            (spheres[a][axis] == spheres[b][axis] && a < b);
                   });
  n.first = buildNode(spheres, first, half);
  n.right = buildNode(spheres, first + half, count - half);
  nodes_[index] = n;
  return index;
}

}  // namespace dpc
