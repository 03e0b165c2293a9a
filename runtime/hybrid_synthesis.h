// Hybrid rendering for many sources: each source's IR holds only its early part (direct sound,
// exact early paths, first reflections: synthesis/hybrid_split.h), and the late part is
// synthesised once per cluster of sources (synthesis/source_clusters.h) into a late bus whose
// input is the sum of the member sources' dry signals, each scaled by its late gain. Source s's
// late gain g_s = sqrt(E_s / E_k), E_s its broadband late energy and E_k the sum over cluster
// k's members, whose late responses add up to the bus's response: each source is rendered with
// exactly its own late energy, in the decay and directions its cluster shares (Schissler &
// Manocha, ACM TOG 36(1) 2016, section 6). Per frame that is S short syntheses and at most B
// full-length ones instead of S full-length ones, and the audio side convolves S short IRs and
// B long ones (runtime/audio_stage.h).
//
// Threads: construction on the control thread (synthesisers, FFTW plans; allocates; throws as
// makeSpatialSynthesizer does, runtime/output_format.h); prepare() on the propagation thread,
// without allocation after the first frames (the synthesisers' own reserves). No errors in
// prepare(). prepare() synthesises each source's early part as a job of its own in a free
// worker workspace (runtime/workspace_slots.h), concurrently with one job for the buses, on the
// tracing threads. The buses' job splits every source serially, in source order (the late
// buses' responses are sums in that order whatever the threads), then synthesises the buses'
// late IRs; spatial output splits before the jobs (its early jobs read the early responses
// the split makes). The IRs are the same bits for any number of workers.
// Memory: per worker workspace, mono: one early synthesiser's workspace; spatial: a workspace
// copy of the early spatial synthesiser (SpatialIrSynthesizer::workspaceCopy: its band signals
// shared). Spatial output also keeps each source's early directional response between the
// serial split and the early jobs (K x early bins x 8 floats per source).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "common/impulse_response.h"
#include "engine/simulation.h"
#include "runtime/kept_irs.h"
#include "runtime/late_shape.h"
#include "runtime/workspace_slots.h"
#include "scene/scene.h"
#include "synthesis/hybrid_split.h"
#include "synthesis/mono_synthesizer.h"
#include "synthesis/source_clusters.h"
#include "synthesis/spatial_synthesizer.h"

namespace dpc {

class BakedPlayback;

/// Whether a scene renders hybrid: `rendering` kHybrid, or kAuto with more sources than late
/// buses (below that, every source could have its own bus and nothing would be saved).
bool rendersHybrid(const AudioSettings& audio, size_t sources);

/// Counts of one listener's hybrid rendering, cumulative over frames.
struct HybridCounts {
  uint64_t frames = 0;
  uint64_t lateDirect = 0;    ///< direct sounds arriving after the early part (rendered late)
  uint64_t lateArrivals = 0;  ///< exact arrivals (direct sound included) rendered late
  int occupiedBuses = 0;      ///< clusters with members, last frame
  double maxAngularRadiusDegrees = 0.0;  ///< largest cluster's angular radius, last frame
  uint64_t switches = 0;     ///< sources that changed cluster (SourceClusters::switches)
  uint64_t forcedJoins = 0;  ///< sources put in a cluster for want of a bus
  uint64_t busesSynthesized = 0;  ///< late bus IRs synthesised
  uint64_t busesKept = 0;         ///< late bus IRs kept from an earlier frame (reuseLateBuses)
};

/// What a render reports of its hybrid rendering (all zero when it rendered per source).
struct HybridReport {
  bool on = false;
  double earlySeconds = 0.0;  ///< length of each source's early part
  int buses = 0;              ///< late buses per listener
  HybridCounts counts;        ///< the played (first rendered) listener's
};

class HybridSynthesis {
 public:
  /// channels: the output's IR channels; spatial: the full-length spatial synthesiser the
  /// stage made (nullptr for mono output), used for the late buses; earlySeconds: the early
  /// part's length (hybridEarlyLength). listeners: how many listeners get clusters (more are
  /// added by prepare() on demand, allocating once).
  /// The sources' early parts are synthesised through `parallel`, each as a job of its own in
  /// one of max(workers, 2) workspaces (as many as jobs run at once; the IRs are the same for
  /// any workers), concurrently with the late buses; `parallel` must stay callable while this
  /// object is used and run at most `workers` jobs at once. Default: on the calling thread.
  /// build: the mono synthesisers' (IrSynthesizer::Build); complete() finishes a kFirstIr
  /// build.
  HybridSynthesis(const SceneDesc& scene, const PropagationSettings& settings, double roomVolume,
                  SpatialIrSynthesizer* spatial, double earlySeconds, size_t listeners,
                  int workers = 1, SpatialIrSynthesizer::ParallelFor parallel = {},
                  IrSynthesizer::Build build = IrSynthesizer::Build::kComplete);
  ~HybridSynthesis();

  /// Completes the mono synthesisers of a kFirstIr build (IrSynthesizer::complete), in the
  /// construction's concurrent groups; nothing when complete or spatial. Between frames, on
  /// the thread that runs prepare(); allocates; throws as construction does.
  void complete();
  bool completed() const;

  size_t earlySamples() const { return earlySamples_; }
  /// Samples of a late bus's IR (the whole IR length).
  size_t lateSamples() const;
  int buses() const { return buses_; }
  const HybridSplit& split() const { return split_; }
  /// The early parts' spatial synthesiser of worker workspace 0 (nullptr for mono output).
  SpatialIrSynthesizer* earlySpatial() {
    return earlySpatial_.empty() ? nullptr : earlySpatial_.front().get();
  }

  /// One frame for `listener`: early[s] (earlySamples()) per source, late[k] (full length)
  /// per bus, gain[s] and bus[s] (the late gain and bus of source s). sources: the
  /// sources' world positions; listenerPosition metres. baked: the attached bake or nullptr.
  void prepare(const Simulation& sim, size_t listener, const glm::vec3& listenerPosition,
               std::span<const glm::vec3> sources, BakedPlayback* baked,
               std::vector<ImpulseResponse>& early,
               std::vector<ImpulseResponse>& late, std::span<float> gain,
               std::span<int> bus);

  /// From now on a late bus keeps the IR it played while its response's shape (LateShape:
  /// each band's decay and the spectrum, apart from the level) stays within toleranceDb (> 0)
  /// of the shape that IR was made from; its sources' gains follow the level exactly. A live
  /// session's choice: a frame then synthesises only the buses whose late field changed.
  /// Control thread, before the frames; no allocation.
  void reuseLateBuses(double toleranceDb) { keepToleranceDb_ = toleranceDb; }
  /// The identity of the IR bus k of listener l holds since its last synthesis: unique over
  /// this object's syntheses (any listener), 0 before the first. An IR set whose partitions
  /// were made from the IR of that identity need not partition it again. Propagation thread.
  uint64_t busIrId(size_t listener, int k) const {
    return listener < made_.size() ? made_[listener][size_t(k)].id : 0;
  }

  /// From now on a source's early IR is kept while what it is made from matches the IR's
  /// signature within toleranceDb (> 0; EarlySignature::matches: the same exact arrivals at
  /// the same delays, levels within toleranceDb, the energy per band and time segment within
  /// toleranceDb). A live session's choice: with nothing moving, a frame then synthesises only
  /// the early parts whose paths changed. 0: every early part every frame. Control thread,
  /// before the frames; no allocation.
  void reuseEarlyParts(double toleranceDb) { early_.setTolerance(toleranceDb); }
  /// The identity of the early IR source s of listener l holds since its last synthesis, as
  /// busIrId; 0 while early parts are not kept (every frame's is new). Propagation thread.
  uint64_t earlyIrId(size_t listener, size_t s) const { return early_.id(listener, s); }
  /// Listener l's early IRs synthesised and kept (reuseEarlyParts), cumulative.
  KeptIrs::Counts earlyCounts(size_t listener) const { return early_.counts(listener); }

  const HybridCounts& counts(size_t listener) const { return counts_.at(listener); }
  /// The report for listener l (a listener never prepared reports zero counts).
  HybridReport report(size_t listener) const;
  const SourceClusters& clusters(size_t listener) const { return *clusters_.at(listener); }

 private:
  struct Scratch;
  /// Spatial output: source s's late part into bus k's response and its early part into its
  /// slot of earlyDirs (serial: buses are shared, the bake's reads too); returns its late
  /// energy and counts whether its direct sound went late.
  double splitSpatial(const Simulation& sim, size_t s, size_t listener, int k,
                      BakedPlayback* baked);
  /// Spatial output: source s's early IR from its slot into early with worker w's synthesiser.
  void synthesizeSpatialEarly(const Simulation& sim, size_t s, size_t listener, size_t w,
                              ImpulseResponse& early);
  /// Mono output: source s's late part into bus k's response (serial: buses are shared);
  /// returns its late energy and counts whether its direct sound went late.
  double addMonoLate(const Simulation& sim, size_t s, size_t listener, int k, BakedPlayback* baked);
  /// Mono output: source s's early IR into early (channel 0) with worker w's scratch.
  void synthesizeMonoEarly(const Simulation& sim, size_t s, size_t listener, size_t w,
                           BakedPlayback* baked, ImpulseResponse& early);
  /// Every source's late share, serially in source order (busEnergy, lateEnergy).
  void splitSources(const Simulation& sim, size_t listener, BakedPlayback* baked,
                    std::span<const int> bus);
  /// The buses (updateBuses; for mono output after splitSources) as one job and every
  /// source's early IR as one more, through parallel_, each early job in a free worker
  /// workspace (slots_).
  void synthesizeAll(const Simulation& sim, size_t listener, BakedPlayback* baked,
                     std::span<const int> bus, std::vector<ImpulseResponse>& early,
                     std::vector<ImpulseResponse>& late);
  /// The number of early worker groups for `workers` threads and `sources` (one without
  /// `parallel`).
  static size_t groupCount(bool parallel, int workers, size_t sources);
  /// Spatial output: the early parts' synthesiser and its workspace copies, one per group.
  void buildSpatial(const SceneDesc& scene, const PropagationSettings& settings,
                    double roomVolume, double earlySeconds, int workers,
                    SpatialIrSynthesizer::ParallelFor parallel);
  /// Mono output: the early parts' synthesisers in worker groups and the late buses', built
  /// concurrently; earlySamples_.
  void buildMono(const SceneDesc& scene, const PropagationSettings& settings, double roomVolume,
                 double earlySeconds, int workers, SpatialIrSynthesizer::ParallelFor parallel,
                 IrSynthesizer::Build build);
  /// Runs late() and group(w) for every worker group w concurrently (threads of their own:
  /// at least two groups at once whatever the tracing threads); rethrows the first error.
  void concurrently(const std::function<void()>& late,
                    const std::function<void(size_t)>& group) const;
  /// Bus k's late IR from its accumulated response into late[k].
  void synthesizeBus(int k, ImpulseResponse& late);
  /// Every bus of the listener: synthesised, or kept while its shape holds (reuseLateBuses).
  void updateBuses(size_t listener, std::vector<ImpulseResponse>& late);
  void ensureListener(size_t listener, size_t sources);
  /// Every IR made so far no longer stands (the synthesisers changed: complete()).
  void forgetMade();
  /// Empties the buses' late responses (in the listener's frame and bins). No allocation after
  /// the first frame.
  void prepareBuses(const Simulation& sim, size_t listener);

  HybridSplit split_;
  int buses_;
  double clusterAngle_;
  size_t earlySamples_ = 0;
  SpatialIrSynthesizer* spatial_ = nullptr;                ///< late buses (spatial output)
  /// Early parts (spatial output): per worker workspace, [0] the original, then copies.
  std::vector<std::unique_ptr<SpatialIrSynthesizer>> earlySpatial_;
  std::vector<std::unique_ptr<IrSynthesizer>> earlyMono_;  ///< per source (mono output)
  /// Mono output: the worker groups' workspaces (those of earlyMono_[w], w < groups), lent to
  /// each early synthesis by slot.
  std::vector<IrSynthesizer::Workspace> monoWorkspaces_;
  WorkspaceSlots slots_;  ///< which worker workspaces (and WorkerScratch) are in use
  std::vector<std::unique_ptr<IrSynthesizer>> lateMono_;   ///< per bus (mono output)
  std::unique_ptr<Scratch> scratch_;
  struct WorkerScratch;
  std::vector<WorkerScratch> workers_;  ///< early parts: one per worker workspace
  SpatialIrSynthesizer::ParallelFor parallel_;
  std::vector<std::unique_ptr<SourceClusters>> clusters_;  ///< per listener
  std::vector<HybridCounts> counts_;
  /// What a bus's playing IR was made from: its response's shape and energy (valid once made).
  struct BusMade {
    LateShape shape;
    double energy = 0.0;
    bool valid = false;
    uint64_t id = 0;  ///< busIrId
  };
  uint64_t lastBusIrId_ = 0;
  std::vector<std::vector<BusMade>> made_;  ///< per listener, per bus
  double keepToleranceDb_ = 0.0;            ///< 0: every bus synthesised every frame
  KeptIrs early_;  ///< the sources' early IRs kept (reuseEarlyParts)
};

}  // namespace dpc
