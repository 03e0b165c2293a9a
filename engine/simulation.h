// Simulation: one propagation frame for every source of a scene, as the renderer, the tests
// and dpc-bench all run it. Owns the geometry tables, the tracer (Embree), the propagator and
// one estimator (diffuse path cache or plain path tracing) per source-listener pair; produces
// each pair's energy response (1 ms bins, ir_length long) and analytic direct sound. Several
// listeners are traced in one pass: every source's rays are tested against all listener
// spheres (docs/dynamic.md).
//
// Exact early specular paths (settings.exactOrder > 0, engine/specular_paths.h): every pair
// also gets the frame's exact all-specular paths up to that order (specularPaths), which the
// energy response then no longer contains. With edge diffraction on, free-standing faces
// smaller than their Fresnel zone reflect a share (engine/small_reflectors.h,
// engine/reflection_scattering.h). Tracing direction (PropagationSettings::tracing): from the
// sources, every source's rays are traced once and tested against every listener sphere; from
// the listeners, every listener's rays against every source sphere (of the listener's radius),
// so a frame's tracing costs one pass per listener whatever the number of sources (Schissler &
// Manocha, ACM TOG 2016; engine/propagation.h, Propagator::setFromListeners). Caches, exact
// paths and results are per pair either way. Directional sources (SourceDesc::directivity):
// the propagator weights each source's rays and direct sound, and each pair's exact paths are
// weighted toward their first reflection point.
//
// Inputs flow down as values: a frame's inputs (where everything is, rays, restarts, skipped
// pairs) come with each runFrame as one FrameInputs (engine/frame_inputs.h), and the
// simulation hands one TraceRequest per emitter to the Propagator; the settings and the scene
// are fixed at construction. Nothing set for one frame carries over to the next.
//
// Propagation thread: construct, runFrame, read results; not safe to share between threads.
// Construction allocates (BVH, tables) and throws std::runtime_error on an Embree error;
// runFrame allocates only while tables grow; it throws std::invalid_argument for inputs that
// do not fit the scene (no listener, a source count other than the scene's).
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "engine/diffraction.h"
#include "engine/direct_cache.h"
#include "engine/energy_response.h"
#include "engine/frame_hits.h"
#include "engine/frame_inputs.h"
#include "engine/geometry.h"
#include "engine/path_cache.h"
#include "engine/propagation.h"
#include "engine/reflection_scattering.h"
#include "engine/sh_energy_response.h"
#include "engine/specular_path_cache.h"
#include "engine/tracer.h"
#include "scene/orientation.h"
#include "scene/scene.h"

namespace dpc {

class Simulation {
 public:
  /// Energy response bin width, seconds.
  static constexpr double kEnergyBinSeconds = 1e-3;

  /// What is fixed for the simulation's life besides the scene and the settings.
  struct Options {
    TraceMode traceMode = kDefaultTraceMode;  ///< the propagator's queries
    /// The path identifier rule; none: the propagator's default (engine/patch.h).
    std::optional<PathKeyRule> keyRule;
  };

  /// Uses scene.mesh, materials, sources, listeners[0].radius (runFrame(position)) and the
  /// propagation settings.
  explicit Simulation(const SceneDesc& scene);
  /// As above with other propagation settings (e.g. command-line overrides) and options.
  Simulation(const SceneDesc& scene, const PropagationSettings& settings, const Options& options);
  Simulation(const SceneDesc& scene, const PropagationSettings& settings)
      : Simulation(scene, settings, Options{}) {}

  struct SourceResult {
    EnergyResponse energy;  ///< this frame's estimate, 1/m^2 per 1 ms bin and band
    DirectSound direct;
    /// Indices in diffraction()->edges() of the edges whose paths `direct` sums this frame
    /// (EdgeDiffraction::apply; empty without diffraction).
    std::vector<uint32_t> diffractionEdges;
    TraceStats trace;
    size_t cacheEntries = 0;
    size_t cacheBytes = 0;
    size_t cacheCoarseEntries = 0;    ///< DPC coarse-store entries (merged path entries)
    size_t cacheBudgetBytes = 0;      ///< DPC memory budget, bytes (0: no cache)
    uint64_t cacheMergedEntries = 0;  ///< path entries merged by the budget, cumulative
    size_t cachePoolBytes = 0;        ///< the engine's cache pool budget, bytes (shared by pairs)
    size_t cachePoolUsedBytes = 0;    ///< the pool's bytes held by all pairs after this frame
    uint64_t cachePoolRefusals = 0;   ///< this pair's table growths the full pool refused
    double cacheCoarseEnergyFraction = 0.0;  ///< the response's share from the coarse store
    double traceSeconds = 0.0;               ///< wall time of this frame's ray tracing
    double estimatorSeconds = 0.0;           ///< grouping hits + cache update + readout
    double directSeconds = 0.0;              ///< direct sound with edge diffraction
    // Exact specular paths (all 0 while exactOrder is 0):
    size_t specularPaths = 0;         ///< valid exact paths this frame (specularPaths())
    size_t specularCandidates = 0;    ///< unique sequences the source's rays proposed
    size_t specularCacheEntries = 0;  ///< sequences the pair keeps across frames
    uint64_t specularOverflow = 0;    ///< cumulative: sequences refused by full tables
    double specularSeconds = 0.0;     ///< wall time of this pair's validation
    /// With recordSurfaces(true): the frame's estimate per surface, Sum I / rays (1/m^2 per
    /// band, the response's scale) of the hits the estimator took this frame, by the triangle
    /// each path reflected from last (not those an exact path replaces); summed over surfaces,
    /// this frame's path-traced energy. Empty otherwise and for a skipped pair.
    SurfaceTally surfaces;
  };

  /// One frame (docs/design.md, "World state"): every source's rays traced once and tested
  /// against every listener of `inputs` (from the sources), or every listener's rays against
  /// every source (from the listeners, PropagationSettings::tracing); each source-listener
  /// pair's estimator updated, its direct sound (with edge diffraction) and exact specular
  /// paths computed. Pair (s, l)'s results: result(s, l), directional(s, l), specularPaths(s, l).
  /// The first frame with more listeners than before allocates their caches and responses.
  /// Skipped pairs (FrameInputs::skippedPairs, played from a bake): the estimator is not
  /// updated and the energy (and directional) response is empty; the direct sound, edge
  /// diffraction and exact specular paths are computed as every pair's. From the sources, a
  /// source skipped for every listener traces no ray; from the listeners, a listener's pass
  /// leaves the skipped sources' spheres out (and, with none left, is not traced). The exact
  /// paths of a pair that no ray of this frame served take their candidates from one
  /// Propagator::proposeSpecular pass per listener. A pair traced again after skipped frames
  /// starts its path cache over, as a restart does: its entries are as old as its last traced
  /// frame, when the listener may have stood elsewhere; its exact-path cache, kept live, stays.
  void runFrame(const FrameInputs& inputs);
  /// The inputs of a frame with the scene's sources (or `sources`, one per source) and one
  /// listener at listenerPosition with the scene's first listener's radius; nothing else
  /// changed. Any thread; allocates.
  FrameInputs inputsAt(const glm::vec3& listenerPosition) const {
    return inputsAt(listenerPosition, sourcePositions_);
  }
  FrameInputs inputsAt(const glm::vec3& listenerPosition,
                       const std::vector<glm::vec3>& sources) const;
  /// The same for several listeners (index l: listener l).
  static FrameInputs inputsAt(std::span<const ListenerSphere> listeners,
                              const std::vector<glm::vec3>& sources);
  /// runFrame(inputsAt(...)): the conveniences of tests and benchmarks.
  void runFrame(const glm::vec3& listenerPosition) { runFrame(inputsAt(listenerPosition)); }
  void runFrame(const glm::vec3& listenerPosition, const std::vector<glm::vec3>& sources) {
    runFrame(inputsAt(listenerPosition, sources));
  }
  void runFrame(std::span<const ListenerSphere> listeners, const std::vector<glm::vec3>& sources) {
    runFrame(inputsAt(listeners, sources));
  }

  /// Starts over as a Simulation constructed with settings().seed = seed would: frame count 0,
  /// every cache emptied, so the following frames are bit-identical to a fresh one's while the
  /// geometry, tracer and edge tables are kept (independent runs at many points, e.g. the
  /// probes of a bake). Propagation thread, between frames; no allocation.
  void restart(uint64_t seed);
  /// The seed of the running frames (settings().seed, or the last restart's).
  uint64_t seed() const { return seed_; }

  /// Whether the last frame skipped pair (source, listener) (FrameInputs::skippedPairs).
  bool skipped(size_t source, size_t listener) const {
    const size_t pair = listener * sourceCount_ + source;
    return pair < skip_.size() && skip_[pair] != 0;
  }

  /// Also produce, per source, a DirectionalEnergyResponse over these listener-frame
  /// directions (for spatial IR synthesis). Allocates.
  void enableDirectional(const std::vector<glm::vec3>& listenerDirections);
  /// Valid after runFrame when enableDirectional was called.
  const DirectionalEnergyResponse& directional(size_t source, size_t listener = 0) const {
    return directional_[listener * sourceCount_ + source];
  }
  bool hasDirectional() const { return !directions_.empty(); }
  /// Also produce, per pair, the response's spherical-harmonic energy of `order` in bins of
  /// binSeconds (engine/sh_energy_response.h; directions in the frame of a listener at yaw 0,
  /// pitch 0), from each arrival's own direction as the estimator reads it out. Allocates.
  void enableShEnergy(int order, double binSeconds);
  /// Valid after runFrame when enableShEnergy was called.
  const ShEnergyResponse& shEnergy(size_t source, size_t listener = 0) const {
    return shEnergy_[listener * sourceCount_ + source];
  }

  /// Source `source`'s result for listener `listener` (< listenerCount()). The trace statistics
  /// (rays, segments, trace time) are those of the pass that traced the pair (the source's,
  /// or the listener's when tracing from the listeners), repeated for every pair of that pass;
  /// listenerHits counts all its spheres' hits. frameTrace() counts each pass once.
  const SourceResult& result(size_t source, size_t listener = 0) const {
    return results_[listener * sourceCount_ + source];
  }
  /// Source `source`'s exact specular paths to listener `listener` in the last frame
  /// (engine/specular_paths.h): order 1..exactOrder, sorted by length; delaySeconds in seconds,
  /// intensity per band in 1/m^2 relative to source power (DirectSound's scale), direction a
  /// unit vector from the listener toward the last reflection point, key stable across frames.
  /// Empty while settings().exactOrder is 0. The reference stays valid, and the vector keeps
  /// its capacity (no allocation), until the next runFrame. Propagation thread.
  const std::vector<SpecularPath>& specularPaths(size_t source, size_t listener = 0) const;
  /// Whether each pair's SourceResult::surfaces is recorded from the next frame on (off by
  /// default: it costs a hash-map insertion per hit). Propagation thread, between frames.
  void recordSurfaces(bool on) { recordSurfaces_ = on; }
  /// The static mesh's diffracting edges (EdgeDiffraction), or null when
  /// settings().diffraction is off. Any thread; fixed at construction.
  const EdgeDiffraction* diffraction() const { return diffraction_.get(); }
  /// The last frame's tracing: its passes' rays, segments and sphere hits summed, each pass
  /// once (a pair's result repeats its pass's statistics; per source from the sources, per
  /// listener from the listeners).
  const TraceStats& frameTrace() const { return frameTrace_; }
  /// Where the last runFrame's wall time went, seconds on the steady clock (the frame
  /// profile: runtime/frame_profile.h). trace: the tracing passes (Propagator::traceFrame and
  /// proposeSpecular); pairs: every pair's finishing after its pass, run concurrently on the
  /// tracing threads (direct sound, edge diffraction, exact paths, estimator); pool: the
  /// cache pool's deferred growths. The pairs' own times, summed over pairs (CPU seconds
  /// across threads): direct sound with edge diffraction, exact-path validation and the
  /// estimator (grouping, cache update and read-out).
  struct FrameTimes {
    double trace = 0.0, pairs = 0.0, pool = 0.0;
    double directCpu = 0.0, exactCpu = 0.0, estimatorCpu = 0.0;
  };
  const FrameTimes& frameTimes() const { return frameTimes_; }
  size_t sourceCount() const { return sourceCount_; }
  /// Listeners the last runFrame traced (at least 1).
  size_t listenerCount() const { return listenerCount_; }
  uint64_t framesRun() const { return frame_; }
  const Geometry& geometry() const { return *geometry_; }
  const Tracer& tracer() const { return *tracer_; }
  Propagator& propagator() { return *propagator_; }
  const PropagationSettings& settings() const { return settings_; }
  /// Bounding-box volume of the mesh, m^3 (used for the Dirac sequence density).
  double boundingVolume() const;

 private:
  /// Caches, responses and groups for `listeners` listeners (grows only).
  void reserveListeners(size_t listeners);
  /// The frame's inputs that are state for its duration: object poses into the tracer,
  /// sources' forward axes, listeners' orientations, restarts, the skip mask and the rays.
  void applyInputs(const FrameInputs& inputs);
  /// The request of one emitter's trace this frame (rays, seed, frame, origin).
  TraceRequest requestFor(uint32_t emitter, const glm::vec3& origin) const;
  /// Per source, a trace's hits in one pass from each source (rays from the sources).
  void traceFromSources(std::span<const ListenerSphere> listeners,
                        const std::vector<glm::vec3>& sources);
  /// The same with one pass from each listener (rays from the listeners).
  void traceFromListeners(std::span<const ListenerSphere> listeners,
                          const std::vector<glm::vec3>& sources);
  /// Empties one pair's path and exact-path caches (a teleport).
  void restartPair(size_t pair);
  /// Every pair of source `source` (of listener `listener`) starts over.
  void restartSource(size_t source);
  void restartListener(size_t listener);
  /// Whether source s is skipped for each of `listeners` listeners (traces no ray).
  bool skippedForAll(size_t s, size_t listeners) const;
  /// From the sources: the pairs of the sources that traced no ray this frame (untraced_),
  /// with exact-path candidates from one proposal pass per listener.
  void finishUntraced(std::span<const ListenerSphere> listeners,
                      const std::vector<glm::vec3>& sources);
  /// From the listeners: the sources traced for listener l (not skipped) into the pass's
  /// compacted spheres, groups, exact sets, patterns and key ids; returns their count.
  size_t compactSources(size_t l, const ListenerSphere& listener,
                        const std::vector<glm::vec3>& sources, size_t S);
  /// The pair's arrival sink for this frame (directional and/or SH energy, cleared), or null.
  ArrivalSink* pairSink(size_t pair, size_t listener);
  /// The estimator's share of finishPair: the update, or for a skipped pair nothing (and a
  /// restart of its path cache when it is traced again).
  void updateOrIdle(size_t pair, const FrameGroups& groups, SourceResult& r, ArrivalSink* dir);
  /// Adds one tracing pass to frameTrace_ and its wall time to frameTimes_.
  void addPass(const TraceStats& t, double seconds);
  /// Runs finishPair for `count` pairs on the tracing threads; wall time into frameTimes_.pairs.
  void finishPairs(size_t count, const std::function<void(size_t)>& finish);
  /// frameTimes_'s CPU sums over the pairs of `listeners` listeners.
  void sumPairTimes(size_t listeners);
  /// Per-source group buffers and exact-path set pointers (grows only).
  void reserveSourceGroups();
  /// Source s and listener l after the trace: direct sound (with edge diffraction) and the
  /// estimator update of `groups` (the pair's hits this frame) into their pair's result.
  /// Touches only that pair's data.
  void finishPair(size_t s, size_t l, const glm::vec3& source, const ListenerSphere& listener,
                  const TraceStats& trace, double traceSeconds, const FrameHits& hits,
                  FrameGroups& groups);
  /// How long an exact path's sequence that is neither valid nor proposed is kept: the DPC's
  /// tau, and none for plain path tracing, which keeps nothing from frame to frame (so that
  /// tau = 0 is plain path tracing, exact paths included).
  double exactPathRetention() const {
    return settings_.estimator == Estimator::kDpc ? double(settings_.cacheTau) : 0.0;
  }
  /// Adds the frame's groups to pair's estimator; its energy response into r.energy (and dir).
  void updateEstimator(size_t pair, const FrameGroups& groups, SourceResult& r,
                       ArrivalSink* dir);
  /// The pair's exact specular paths for this frame, statistics into r.
  void updateSpecular(size_t pair, const glm::vec3& source, const ListenerSphere& listener,
                      SourceResult& r);

  const PropagationSettings settings_;
  float listenerRadius_;
  uint64_t seed_;  ///< seed()
  int rays_ = 1;   ///< this frame's rays per emitter (FrameInputs::raysPerEmitter)
  bool includeDirectRays_ = false;  ///< this frame's FrameInputs::includeDirectRays
  std::vector<glm::vec3> sourcePositions_;  ///< the scene's, for inputsAt
  std::vector<Directivity> directivities_;  ///< per source, the scene's
  std::vector<glm::vec3> initialForwards_;  ///< per source, at scene time 0
  std::vector<glm::vec3> sourceForwards_;   ///< per source this frame, unit forward (world)
  std::vector<Pose> initialObjectPoses_;    ///< per object, at scene time 0
  bool objectsMoved_ = false;               ///< the tracer holds poses other than the initial
  std::unique_ptr<Geometry> geometry_;
  std::unique_ptr<Tracer> tracer_;
  std::unique_ptr<Propagator> propagator_;
  std::unique_ptr<EdgeDiffraction> diffraction_;  ///< first-order edge paths into the direct sound
  std::unique_ptr<ReflectionScattering> smallFaces_;  ///< free-standing faces, with diffraction_
  DirectCache directCache_;  ///< pairs' direct sounds, kept while nothing they depend on moved
  size_t sourceCount_ = 0;
  size_t listenerCount_ = 1;  ///< listeners of the last frame
  size_t reserved_ = 0;       ///< listeners with caches and responses
  // Per source-listener pair, index listener * sourceCount_ + source:
  std::unique_ptr<CachePool> cachePool_;  ///< settings.cachePoolMb, shared by every pair's cache
  std::vector<std::unique_ptr<DiffusePathCache>> caches_;
  std::vector<SourceResult> results_;
  std::vector<DirectionalEnergyResponse> directional_;
  std::vector<ShEnergyResponse> shEnergy_;  ///< per pair, enableShEnergy
  std::vector<ArrivalTee> tees_;             ///< per pair: directional_ and shEnergy_ both
  int shOrder_ = -1;                         ///< enableShEnergy's order (-1: off)
  double shBinSeconds_ = 0.01;
  PathTracingEstimator pathTracing_;
  bool recordSurfaces_ = false;
  // Tracing from the sources: per listener, this source's hits, and the grouping scratch.
  std::vector<FrameHits> hits_;
  std::vector<FrameHits*> hitPtrs_;  ///< &hits_[l]
  std::vector<FrameGroups> groups_;
  // Tracing from the listeners: per source, this listener's hits and grouping scratch, and the
  // source spheres.
  std::vector<FrameHits> sourceHits_;
  std::vector<FrameHits*> sourceHitPtrs_;
  std::vector<FrameGroups> sourceGroups_;
  std::vector<ListenerSphere> sourceSpheres_;
  // The same compacted to the sources traced for the listener (FrameInputs::skippedPairs):
  std::vector<FrameHits*> liveHitPtrs_;
  std::vector<Directivity> livePatterns_;
  std::vector<glm::vec3> liveForwards_;
  std::vector<uint32_t> liveIds_;  ///< source index of each compacted sphere (path keys)
  std::vector<uint8_t> skip_;      ///< this frame's FrameInputs::skippedPairs, per pair
  std::vector<uint8_t> idle_;      ///< per pair: skipped in its last frame
  std::vector<size_t> untraced_;   ///< from the sources: this frame's sources traced for none
  /// What a pair skipped for every listener is handed (it reads none).
  const FrameHits noHits_;
  FrameGroups noGroups_;
  std::vector<glm::vec3> directions_;    ///< enableDirectional's listener-frame directions
  std::vector<Orientation> orientations_{1};  ///< per listener, this frame's
  // Exact specular paths (null / empty while exactOrder is 0):
  std::unique_ptr<SpecularScene> specularScene_;
  std::unique_ptr<SpecularCandidates> specularCandidates_;  ///< this source's frame
  std::vector<std::unique_ptr<SpecularPathCache>> specularCaches_;  ///< per pair
  uint64_t specularCandidateOverflow_ = 0;  ///< cumulative over sources and frames
  uint64_t frame_ = 0;
  TraceStats frameTrace_;
  FrameTimes frameTimes_;
};

}  // namespace dpc
