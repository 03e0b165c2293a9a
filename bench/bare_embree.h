// The yardstick for dpc-bench: a bare Embree loop that traces the same rays (same count, same
// max order, cosine-sampled diffuse bounces, no listener test, no patch ids, no hashing, no
// cache) through the same Tracer, with the same threads and chunking as Propagator, either
// one ray at a time (rtcIntersect1) or 16 rays of a chunk in lockstep (rtcIntersect16, a lane
// whose ray ends takes the chunk's next ray), matching Propagator's TraceMode.
// Propagation/bench thread; no allocation per ray (one small vector per call); no errors.
#pragma once

#include <cstdint>
#include <glm/vec3.hpp>

#include "engine/tracer.h"

namespace dpc::bench {

struct BareResult {
  uint64_t segments = 0;
  double seconds = 0.0;
};

/// Which Embree query the bare loop uses.
enum class BareMode {
  kScalar,    ///< rtcIntersect1, one ray to completion at a time
  kPacket16,  ///< rtcIntersect16 over 16 rays of a chunk at once (Tracer batch intersect)
};

/// Traces `rays` paths of up to maxOrder reflections from `source` on `threads` threads
/// (0 = all cores). Both modes trace the same rays (per-ray random streams) and report the
/// same segment count up to rounding differences of the kernels.
BareResult traceBare(const Tracer& tracer, const glm::vec3& source, int rays, int maxOrder,
                     int threads, uint64_t seed, BareMode mode = BareMode::kScalar);

}  // namespace dpc::bench
