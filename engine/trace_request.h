// What one emitter's trace for one frame is given and gives back (engine/propagation.h's
// Propagator::traceFrame): the request as a plain value, the query mode, the counts, and the
// analytic direct sound. Units: metres, seconds; directions unit vectors in the world frame.
#pragma once

#include <cstdint>
#include <glm/vec3.hpp>
#include <span>

#include "common/bands.h"
#include "engine/frame_inputs.h"
#include "scene/directivity.h"

namespace dpc {

/// Analytic direct sound: line of sight, 1/(4 pi r^2), air absorption.
struct DirectSound {
  bool visible = false;
  float distance = 0.f;      ///< metres (clamped below at R/2: see directSound())
  float delaySeconds = 0.f;  ///< distance / c
  Bands intensity{0.f};      ///< 1/m^2 relative to source power; zero when occluded
  glm::vec3 direction{0.f};  ///< unit vector from the listener toward the source
  /// Transmitting surfaces the straight path crosses (engine/transmission.h): 0 for a line of
  /// sight; > 0 when visible only through surfaces, the intensity then carrying their
  /// transmittances' product.
  int crossings = 0;
  /// True when the path was counted blocked after kMaxDirectCrossings surfaces.
  bool crossingCapped = false;
  /// Edge diffraction with the line of sight blocked (engine/edge_chain.h): the edges near it
  /// that no path round edges in series was laid from (past kChainSeeds, the farthest) plus
  /// the chains not tried (past kChainTrials) and those that would wrap round more than
  /// kChainEdges edges (a row of more bodies in line than that).
  uint32_t chainsLeftOut = 0;
  /// A free line of sight (no surface in between): what diffraction's shadow boundary needs.
  bool lineOfSight() const { return visible && crossings == 0; }
};

struct TraceStats {
  uint64_t rays = 0;          ///< rays emitted
  uint64_t segments = 0;      ///< ray segments traced (closest-hit queries)
  uint64_t listenerHits = 0;  ///< segment-sphere crossings, summed over the listeners
  /// Energy per band that rays still carried (air absorption applied) when the reflection
  /// order bound (PropagationSettings::maxOrder) ended them, summed over the rays: lost to
  /// the response. A ray leaves with 1 per band on average, so maxOrderEnergy / rays is the
  /// emitted energy's share that the bound cut off.
  Bands maxOrderEnergy{0.f};
  /// The largest band's share of the emitted energy that the reflection order bound cut off
  /// (maxOrderEnergy / rays; 0 before any ray): what the max_order warning reads.
  double maxOrderShare() const {
    return rays > 0 ? double(maxOrderEnergy.max()) / double(rays) : 0.0;
  }
  /// Adds another pass's counts (a frame's passes, summed).
  TraceStats& operator+=(const TraceStats& o) {
    rays += o.rays, segments += o.segments, listenerHits += o.listenerHits;
    maxOrderEnergy += o.maxOrderEnergy;
    return *this;
  }
};

/// How Propagator issues its tracer queries (same physics, same random streams).
enum class TraceMode {
  kScalar,    ///< one ray to completion at a time, single-ray queries (rtcIntersect1)
  kPacket16,  ///< 16 rays of a chunk in lockstep, batch queries (rtcIntersect16)
};

/// The default mode: packets, which trace the same segments and hits faster than single rays
/// (docs/performance.md, "16-wide packets"). Builds may pick scalar with
/// -DDPC_DEFAULT_TRACE_MODE_SCALAR=1.
#if defined(DPC_DEFAULT_TRACE_MODE_SCALAR) && DPC_DEFAULT_TRACE_MODE_SCALAR
inline constexpr TraceMode kDefaultTraceMode = TraceMode::kScalar;
#else
inline constexpr TraceMode kDefaultTraceMode = TraceMode::kPacket16;
#endif

/// One emitter's trace for one frame (Propagator::traceFrame): everything that varies from
/// frame to frame, as a plain value. The spans view the caller's arrays, which must outlive
/// the call. Units: metres; directions unit vectors in the world frame.
struct TraceRequest {
  uint64_t seed = 0;     ///< the run's seed (PropagationSettings::seed or a restart's)
  uint64_t frame = 0;    ///< frame index: with seed and emitter, it selects the random streams
  uint32_t emitter = 0;  ///< the source index (from a listener: the listener index)
  glm::vec3 origin{0.f};  ///< where the rays leave
  int rays = 0;           ///< rays to trace, >= 0
  /// Rays leave a listener and the receivers are the sources (reciprocal tracing, Schissler &
  /// Manocha, "Interactive sound propagation and rendering for large multi-source scenes",
  /// ACM TOG 36(1), 2016): a hit's direction is the ray's first direction (where the sound
  /// arrives from, seen from the listener); receiver l's pattern weights the hit toward the
  /// direction the sound leaves it (minus the ray's direction at the sphere); the specular
  /// sequences are recorded listener first and reversed into source-first order.
  bool fromListener = false;
  /// The emitting source's radiation pattern and forward axis (scene/directivity.h): every
  /// ray's energy is weighted at emission by directivityWeight at its leaving direction. Omni
  /// (the default) applies no weight. Ignored from a listener.
  Directivity pattern;
  glm::vec3 forward{1.f, 0.f, 0.f};
  /// The spheres tested (listeners, or from a listener the sources): hits to receiver l go to
  /// traceFrame's groups[l].
  std::span<const ListenerSphere> receivers;
  /// The identifier receiver l finishes into its hits' path identifiers (pathHashFinish):
  /// ids[l], or l itself when empty. Lets a caller that leaves some spheres out of a pass keep
  /// every other sphere's keys (and so its cache's paths) unchanged.
  std::span<const uint32_t> receiverIds;
  /// From a listener: receiver l's pattern and forward axis (empty: every receiver omni).
  std::span<const Directivity> receiverPatterns;
  std::span<const glm::vec3> receiverForwards;
  /// Segments leaving the origin also count as hits (calibration against 1/(4 pi r^2); the
  /// renderer keeps the analytic direct sound instead).
  bool includeDirectRays = false;
};

}  // namespace dpc
