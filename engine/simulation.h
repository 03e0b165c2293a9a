// Simulation: one propagation frame for every source of a scene, as the renderer, the tests
// and dpc-bench all run it. Owns the geometry tables, the tracer (Embree), the propagator and one
// estimator (diffuse
// path cache or plain path tracing) per source-listener pair; produces each pair's energy
// response (1 ms bins, ir_length long) and analytic direct sound. Several listeners are traced
// in one pass: every source's rays are tested against all listener spheres (docs/dynamic.md).
//
// Exact early specular paths (settings.exactOrder > 0, engine/specular_paths.h): every pair
// also gets the frame's exact all-specular paths up to that order (specularPaths), which the
// energy response then no longer contains.
//
// Tracing direction (PropagationSettings::tracing): from the sources, every source's rays are
// traced once and tested against every listener sphere; from the listeners, every listener's
// rays are traced once and tested against every source sphere (of the listener's radius), so a
// frame's tracing costs one pass per listener whatever the number of sources (Schissler &
// Manocha, ACM TOG 2016; engine/propagation.h, Propagator::setFromListeners). Caches, exact
// paths and results are per pair either way.
//
// Directional sources (SourceDesc::directivity): the propagator weights each source's rays and
// direct sound, and each pair's exact paths are weighted toward their first reflection point.
//
// Propagation thread: construct, runFrame, read results; not safe to share between threads.
// Construction allocates (BVH, tables) and throws std::runtime_error on an Embree error;
// runFrame allocates only while tables grow. No errors otherwise.
#pragma once

#include <memory>
#include <span>
#include <vector>

#include "engine/diffraction.h"
#include "engine/energy_response.h"
#include "engine/geometry.h"
#include "engine/path_cache.h"
#include "engine/propagation.h"
#include "engine/sh_energy_response.h"
#include "engine/specular_paths.h"
#include "engine/tracer.h"
#include "scene/orientation.h"
#include "scene/scene.h"

namespace dpc {

class Simulation {
 public:
  /// Energy response bin width, seconds.
  static constexpr double kEnergyBinSeconds = 1e-3;

  /// Uses scene.mesh, materials, sources, listeners[0].radius (runFrame(position)) and the
  /// propagation settings.
  explicit Simulation(const SceneDesc& scene);
  /// As above with other propagation settings (e.g. command-line overrides).
  Simulation(const SceneDesc& scene, const PropagationSettings& settings);

  struct SourceResult {
    EnergyResponse energy;  ///< this frame's estimate, 1/m^2 per 1 ms bin and band
    DirectSound direct;
    TraceStats trace;
    size_t cacheEntries = 0;
    size_t cacheBytes = 0;
    size_t cacheCoarseEntries = 0;    ///< DPC coarse-store entries (merged path entries)
    size_t cacheBudgetBytes = 0;      ///< DPC memory budget, bytes (0: no cache)
    uint64_t cacheMergedEntries = 0;  ///< path entries merged by the budget, cumulative
    size_t cachePoolBytes = 0;        ///< the engine's cache pool budget, bytes (shared by pairs)
    size_t cachePoolUsedBytes = 0;    ///< the pool's bytes held by all pairs after this frame
    uint64_t cachePoolRefusals = 0;   ///< this pair's table growths the full pool refused
    double cacheCoarseEnergyFraction =
        0.0;                        ///< share of this frame's response from the coarse store
    double traceSeconds = 0.0;      ///< wall time of this frame's ray tracing
    double estimatorSeconds = 0.0;  ///< grouping hits + cache update + readout
    // Exact specular paths (all 0 while exactOrder is 0):
    size_t specularPaths = 0;         ///< valid exact paths this frame (specularPaths())
    size_t specularCandidates = 0;    ///< unique sequences the source's rays proposed
    size_t specularCacheEntries = 0;  ///< sequences the pair keeps across frames
    uint64_t specularOverflow = 0;    ///< cumulative: sequences refused by full tables
    double specularSeconds = 0.0;     ///< wall time of this pair's validation
  };

  /// Traces one frame from every source to a listener at listenerPosition (metres), with the
  /// scene's listener radius; results go to listener index 0.
  void runFrame(const glm::vec3& listenerPosition);
  /// Same, with source positions other than the scene's (one per source).
  void runFrame(const glm::vec3& listenerPosition, const std::vector<glm::vec3>& sources);
  /// One pass for several listeners: each source's rays are traced once and tested against
  /// every sphere in `listeners` (index l = listener l: its own cache per source, path
  /// identifiers carrying l). The first frame with more listeners than before allocates their
  /// caches and responses. Listener l's results: result(source, l), directional(source, l).
  void runFrame(std::span<const ListenerSphere> listeners, const std::vector<glm::vec3>& sources);

  /// Rays per source for the following frames (n >= 1; settings().raysPerFrame follows).
  /// Every estimator normalises a frame by the rays that frame traced (TraceStats::rays), so
  /// frames of different counts average without bias. Propagation thread, between frames;
  /// allocates only if n needs more trace chunks than any frame before.
  void setRaysPerFrame(int n);

  /// Orients the sources for the following frames (one unit quaternion per source, scene
  /// order; the scene's sourceRotationAt): each directional source's forward axis is
  /// rotation * (+x) (scene/directivity.h). Omni sources ignore it. No allocation.
  void setSourceRotations(const std::vector<glm::quat>& rotations);
  /// Starts over as a Simulation constructed with settings().seed = seed would: frame count 0,
  /// every cache emptied, so the following frames are bit-identical to a fresh one's while the
  /// geometry, tracer and edge tables are kept (independent runs at many points, e.g. the
  /// probes of a bake). Propagation thread, between frames; no allocation.
  void restart(uint64_t seed);

  /// Source `source` jumped (a teleport): its pairs' caches (path and exact-path) start over,
  /// so the next frame's responses hold nothing of its old place. Propagation thread, between
  /// frames; no allocation.
  void restartSource(size_t source);
  /// The same for every pair of listener `listener` (a listener index of the frames traced).
  void restartListener(size_t listener);

  /// Pairs whose energy response is not wanted from the next frame on (played from a bake,
  /// runtime/baked_playback.h): skip[l * sourceCount() + s] != 0 skips source s for listener l
  /// (entries beyond skip's size: not skipped; empty, the default: nothing skipped). A skipped
  /// pair's estimator is not updated and its energy (and directional) response is empty; its
  /// direct sound, edge diffraction and exact specular paths are computed as every pair's.
  /// From the sources, a source skipped for every listener traces no ray; from the listeners,
  /// a listener's pass leaves the skipped sources' spheres out (and, with none left, is not
  /// traced). The exact paths of a pair that no ray of this frame served take their candidates
  /// from one Propagator::proposeSpecular pass per listener (at most exact_order segments a
  /// ray, shared by all such sources). A pair traced again after skipped frames starts its path
  /// cache over, as a teleport does: its entries are as old as its last traced frame, when the
  /// listener may have stood elsewhere, and the estimators read out an unbiased response from
  /// a restarted cache's first frame; its exact-path cache, kept live, stays. Propagation
  /// thread, between frames; allocates only while the mask grows.
  void setSkippedPairs(std::span<const uint8_t> skip) { skip_.assign(skip.begin(), skip.end()); }
  /// Whether the last frame skipped pair (source, listener) (setSkippedPairs).
  bool skipped(size_t source, size_t listener) const {
    const size_t pair = listener * sourceCount_ + source;
    return pair < skip_.size() && skip_[pair] != 0;
  }

  /// Moves the scene's objects (one pose per object, scene order) for the following frames
  /// (Tracer::setObjectPose, then commitPoses). No allocation.
  void setObjectPoses(const std::vector<Pose>& poses);

  /// Also produce, per source, a DirectionalEnergyResponse over these listener-frame
  /// directions (for spatial IR synthesis). Allocates.
  void enableDirectional(const std::vector<glm::vec3>& listenerDirections);
  /// Listener 0's orientation for the following frames (world forward/up; see Orientation).
  void setListenerOrientation(const Orientation& orientation) { orientations_[0] = orientation; }
  /// Listener l's orientation for the following frames (grows the table; allocates then).
  void setListenerOrientation(size_t listener, const Orientation& orientation);
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
  /// The last frame's tracing: its passes' rays, segments and sphere hits summed, each pass
  /// once (a pair's result repeats its pass's statistics; per source from the sources, per
  /// listener from the listeners).
  const TraceStats& frameTrace() const { return frameTrace_; }
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
  /// Per source, a trace's hits in one pass from each source (rays from the sources).
  void traceFromSources(std::span<const ListenerSphere> listeners,
                        const std::vector<glm::vec3>& sources);
  /// The same with one pass from each listener (rays from the listeners).
  void traceFromListeners(std::span<const ListenerSphere> listeners,
                          const std::vector<glm::vec3>& sources);
  /// Empties one pair's path and exact-path caches (a teleport).
  void restartPair(size_t pair);
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
  void updateOrIdle(size_t pair, const FrameGroups& groups, SourceResult& r,
                    ArrivalSink* dir);
  /// Adds one tracing pass to frameTrace_.
  void addPass(const TraceStats& t);
  /// Per-source group buffers and exact-path set pointers (grows only).
  void reserveSourceGroups();
  /// Source s and listener l after the trace: direct sound (with edge diffraction) and the
  /// estimator update of `groups` (the pair's hits this frame) into their pair's result.
  /// Touches only that pair's data.
  void finishPair(size_t s, size_t l, const glm::vec3& source, const ListenerSphere& listener,
                  const TraceStats& trace, double traceSeconds, const FrameGroups& groups);
  /// Adds the frame's groups to pair's estimator and reads its energy response into r.energy
  /// (and dir when not null).
  void updateEstimator(size_t pair, const FrameGroups& groups, SourceResult& r,
                       ArrivalSink* dir);
  /// The pair's exact specular paths for this frame, statistics into r.
  void updateSpecular(size_t pair, const glm::vec3& source, const ListenerSphere& listener,
                      SourceResult& r);

  PropagationSettings settings_;
  float listenerRadius_;
  std::vector<glm::vec3> sourcePositions_;
  std::vector<Directivity> directivities_;  ///< per source, the scene's
  std::vector<glm::vec3> sourceForwards_;   ///< per source, unit forward axis (world)
  std::unique_ptr<Geometry> geometry_;
  std::unique_ptr<Tracer> tracer_;
  std::unique_ptr<Propagator> propagator_;
  std::unique_ptr<EdgeDiffraction> diffraction_;  ///< first-order edge paths into the direct sound
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
  std::vector<FrameGroups> groups_;      ///< per listener, this source's frame
  std::vector<FrameGroups*> groupPtrs_;  ///< &groups_[l]
  // Tracing from the listeners: per source, this listener's frame, and the source spheres.
  std::vector<FrameGroups> sourceGroups_;
  std::vector<FrameGroups*> sourceGroupPtrs_;
  std::vector<ListenerSphere> sourceSpheres_;
  // The same compacted to the sources traced for the listener (setSkippedPairs):
  std::vector<FrameGroups*> liveGroupPtrs_;
  std::vector<const tsl::robin_set<uint64_t>*> liveExactSetPtrs_;
  std::vector<Directivity> livePatterns_;
  std::vector<glm::vec3> liveForwards_;
  std::vector<uint32_t> liveIds_;  ///< source index of each compacted sphere (path keys)
  std::vector<uint8_t> skip_;      ///< setSkippedPairs, per pair
  std::vector<uint8_t> idle_;      ///< per pair: skipped in its last frame
  std::vector<size_t> untraced_;   ///< from the sources: this frame's sources traced for none
  FrameGroups noGroups_;           ///< what a skipped pair is handed (it reads none)
  /// Per listener, the traced source's pair's SpecularPathCache::validKeys
  std::vector<const tsl::robin_set<uint64_t>*> exactSetPtrs_;
  std::vector<glm::vec3> directions_;    ///< enableDirectional's listener-frame directions
  std::vector<Orientation> orientations_{1};
  // Exact specular paths (null / empty while exactOrder is 0):
  std::unique_ptr<SpecularScene> specularScene_;
  std::unique_ptr<SpecularCandidates> specularCandidates_;  ///< this source's frame
  std::vector<std::unique_ptr<SpecularPathCache>> specularCaches_;  ///< per pair
  uint64_t specularCandidateOverflow_ = 0;  ///< cumulative over sources and frames
  uint64_t frame_ = 0;
  TraceStats frameTrace_;
};

}  // namespace dpc
