// A bounding volume hierarchy over spheres, for the ray-segment test against many receiver
// spheres (every source sphere when tracing from the listeners): a segment visits the boxes it
// crosses, O(log S) of S spheres when they are spread out, instead of testing all S.
//
// Built top-down by splitting each node's spheres at the median of their centres along the
// box's longest axis (a balanced tree; the spheres move every frame, so it is rebuilt every
// frame in O(S log S)); leaves hold at most kLeafSize spheres. Traversal uses the slab test
// (Kay & Kajiya, "Ray tracing complex scenes", SIGGRAPH 1986) with a fixed-size stack.
//
// Threads: build on one thread, then forEachCandidate from any number of threads (read only).
// Allocation: build grows its tables to the largest sphere count seen, then reuses them;
// forEachCandidate never allocates. No errors.
#pragma once

#include <array>
#include <cstdint>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>
#include <span>
#include <vector>

namespace dpc {

class SphereBvh {
 public:
  static constexpr uint32_t kLeafSize = 4;

  /// spheres: centre (x, y, z, metres) and radius (w, metres, > 0).
  void build(std::span<const glm::vec4> spheres);
  size_t size() const { return order_.size(); }

  /// Calls f(index) for every sphere whose bounding box the segment org + t dir, t in
  /// [0, segEnd] (dir unit, segEnd metres or infinity), crosses: a superset of the spheres it
  /// meets; the caller tests the sphere itself. Order: a fixed traversal order.
  template <class F>
  void forEachCandidate(const glm::vec3& org, const glm::vec3& dir, float segEnd, F&& f) const {
    if (nodes_.empty()) return;
    const glm::vec3 inv = 1.f / dir;
    std::array<uint32_t, 64> stack;
    uint32_t top = 0;
    stack[top++] = 0;
    while (top > 0) {
      const Node& n = nodes_[stack[--top]];
      if (!crosses(n, org, inv, segEnd)) continue;
      if (n.count > 0) {
        for (uint32_t i = n.first; i < n.first + n.count; ++i) f(order_[i]);
      } else {
        stack[top++] = n.first;  // left child; the right one is stored after the left subtree
        stack[top++] = n.right;
      }
    }
  }

 private:
  struct Node {
    glm::vec3 lo{0.f}, hi{0.f};
    uint32_t first = 0;  ///< leaf: first index into order_; inner: left child
    uint32_t count = 0;  ///< leaf: spheres (> 0); inner: 0
    uint32_t right = 0;  ///< inner: right child
  };
  /// Slab test of the segment against n's box; inline, as it runs for every node visited.
  static bool crosses(const Node& n, const glm::vec3& org, const glm::vec3& inv, float segEnd) {
    float t0 = 0.f, t1 = segEnd;
    for (int a = 0; a < 3; ++a) {
      const float ta = (n.lo[a] - org[a]) * inv[a], tb = (n.hi[a] - org[a]) * inv[a];
      const float near = ta < tb ? ta : tb, far = ta < tb ? tb : ta;
      // NaN (a zero direction component with the origin on a slab plane) keeps the box.
      t0 = near > t0 ? near : t0;
      t1 = far < t1 ? far : t1;
    }
    return t0 <= t1;
  }
  uint32_t buildNode(std::span<const glm::vec4> spheres, uint32_t first, uint32_t count);

  std::vector<Node> nodes_;
  std::vector<uint32_t> order_;
};

}  // namespace dpc
