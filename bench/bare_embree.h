// The yardstick for dpc-bench: a bare Embree loop that traces the same rays (same count, same
// max order, cosine-sampled diffuse bounces, no listener test, no patch ids, no hashing, no
// cache) through the same Geometry, with the same threads and chunking as Propagator.
// Propagation/bench thread; no allocation per ray.
#pragma once

#include <cstdint>

#include <glm/vec3.hpp>

#include "engine/geometry.h"

namespace dpc::bench {

struct BareResult {
  uint64_t segments = 0;
  double seconds = 0.0;
};

/// Traces `rays` paths of up to maxOrder reflections from `source` on `threads` threads
/// (0 = all cores).
BareResult traceBare(const Geometry& geometry, const glm::vec3& source, int rays, int maxOrder,
                     int threads, uint64_t seed);

}  // namespace dpc::bench
