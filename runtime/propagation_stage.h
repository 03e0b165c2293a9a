// PropagationStage: the propagation side of the render pipeline (runtime/render_pipeline.h).
// One frame entry: traceWorld(world) traces every scene listener where `world` puts it, with
// every source and object where `world` puts them (the caller assembled the world: the
// trajectories at the frame's time, then whatever a host overrode); prepare(l) then makes
// listener l's IR set. The offline renderer and the live session drive it the same way.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "audio/nonuniform_convolver.h"
#include "common/impulse_response.h"
#include "engine/simulation.h"
#include "runtime/baked_playback.h"
#include "runtime/frame_profile.h"
#include "runtime/hybrid_synthesis.h"
#include "runtime/ir_exchange.h"
#include "runtime/output_format.h"
#include "scene/scene.h"
#include "scene/trajectory.h"
#include "synthesis/mono_synthesizer.h"
#include "synthesis/spatial_synthesizer.h"
#include "wave/wave_join.h"

namespace dpc {

/// Propagation thread side. Construction (control thread) builds the Embree scene, the IR
/// synthesisers (mono per source, or one spatial synthesiser with HRTF or panning filters
/// shared by all sources) and the convolver layout; allocates; throws InputError (e.g. an
/// unreadable SOFA file, named by the scene's audio.hrtf) or std::runtime_error. The scene is
/// shared, read only. The IR sets it fills belong to an IrExchange (makeExchange). The
/// accessors (simulation(), lastIrs(), totals(), ...) belong to the thread that runs the
/// frames; they neither allocate nor throw (lastIrs: std::out_of_range for a listener never
/// traced).
class PropagationStage {
 public:
  /// `planning` chooses the convolver layouts' FFTW plans: estimated (instant; the same
  /// transforms, so the same output bit for bit, on every run) or measured (FFTW times
  /// candidate algorithms at construction, up to a second or so for a 2 s IR: faster
  /// callbacks, for a live session, whose output is not compared bit for bit).
  /// `build`: the mono synthesisers' (IrSynthesizer::Build): kFirstIr leaves most of their
  /// construction to completeSynthesis(), which makes the IRs after it the same bits as a
  /// complete build's (the spatial synthesisers are always built complete).
  PropagationStage(
      std::shared_ptr<const SceneDesc> scene, const PropagationSettings& settings,
      audio::ConvolverLayout::Planning planning = audio::ConvolverLayout::Planning::kEstimate,
      IrSynthesizer::Build build = IrSynthesizer::Build::kComplete);

  /// Completes a kFirstIr build's synthesisers (IrSynthesizer::complete); nothing when they
  /// are complete. Between frames, on the thread that runs them (the hybrid early parts'
  /// groups on threads of their own meanwhile); allocates; throws std::runtime_error when FFTW
  /// cannot plan.
  void completeSynthesis();
  bool synthesisCompleted() const;
  /// The convolver layouts' (layout(), lateLayout()) NonUniformLayout::plansMeasured() and
  /// measurePlans(): for Planning::kMeasureLater, any thread but the audio thread, while
  /// frames run (the sets' partitions and the convolvers take the measured plans as they are
  /// swapped in).
  bool fftPlansMeasured() const;
  void measureFftPlans() const;

  /// The exchange that carries this stage's IR sets to `channels` audio stages: baseSets sets
  /// plus two per partition level beyond the first (a slow level keeps its old and new set
  /// through its crossfade). Control thread; allocates.
  std::unique_ptr<IrExchange> makeExchange(size_t channels, int baseSets) const;

  /// The frame entry (docs/design.md, "World state"): listener l at world.listener*[l] with
  /// the radius of scene.listeners[l] (evaluateWorld gives one per scene listener; a
  /// benchmark may give more: listener l then has the radius of scene listener l mod n);
  /// sources and objects where `world` puts them. Each source's rays are traced once and
  /// tested against all listener spheres; every source-listener pair has its own cache
  /// (docs/dynamic.md, "Several listeners"). Then prepare(l) makes listener l's IR set. world
  /// must hold at least one listener and one entry per scene source and object
  /// (std::invalid_argument otherwise). raysPerEmitter: rays per source (from the listeners:
  /// per listener) this frame; 0: the settings' raysPerFrame. The world becomes one
  /// FrameInputs value for Simulation::runFrame. Propagation thread; allocates only while
  /// tables grow.
  void traceWorld(const WorldState& world, int raysPerEmitter = 0);
  /// Synthesises listener l's IRs from the last traceWorld into lastIrs(l) (hybrid: and
  /// lastLateIrs(l) with the sources' late gains and buses). l < listenerCount()
  /// (std::out_of_range otherwise). Propagation thread; no allocation after the first frame.
  void synthesizeIrs(size_t listener);
  /// synthesizeIrs(l), then partitions and transforms the IRs into `set` (one of
  /// makeExchange()'s, acquired by the caller; set.listener = l). Propagation thread.
  void prepare(size_t listener, IrSet& set);
  /// Listeners the last frame traced.
  size_t listenerCount() const { return simulation_->listenerCount(); }
  const SceneDesc& scene() const { return *scene_; }
  /// The convolver layout of every IrSet's per-source IRs, shared with the audio stages.
  const std::shared_ptr<const audio::NonUniformLayout>& layout() const { return layout_; }
  /// Hybrid rendering: the late buses' layout (full IR length) and their count; else null, 0.
  const std::shared_ptr<const audio::NonUniformLayout>& lateLayout() const { return lateLayout_; }
  int lateBuses() const { return hybrid_ ? hybrid_->buses() : 0; }
  /// Hybrid rendering's synthesis and counts, or nullptr when every source renders whole.
  const HybridSynthesis* hybrid() const { return hybrid_.get(); }
  /// Hybrid rendering: late buses keep their IR while their shape holds within toleranceDb
  /// (HybridSynthesis::reuseLateBuses); nothing without hybrid rendering. Control thread,
  /// before the frames.
  void reuseLateBuses(double toleranceDb) {
    if (hybrid_) hybrid_->reuseLateBuses(toleranceDb);
  }
  /// Each source's own IR (whole, or its early part in hybrid rendering: HybridSynthesis::
  /// reuseEarlyParts) kept while its inputs match what it was made from within toleranceDb
  /// (runtime/kept_irs.h); a kept IR is not partitioned again into a set that holds it. Not
  /// while wave bands are joined (their blend is not part of the inputs compared). 0: every
  /// IR every frame. Control thread, before the frames; no allocation.
  void reuseSourceIrs(double toleranceDb);
  /// The identity of source s's IR for listener l (KeptIrs::id). Propagation thread.
  uint64_t sourceIrId(size_t listener, size_t s) const {
    return hybrid_ ? hybrid_->earlyIrId(listener, s) : whole_.id(listener, s);
  }
  /// Listener l's source IRs synthesised and kept, cumulative. Propagation thread, or any
  /// thread while it is stopped.
  KeptIrs::Counts sourceIrCounts(size_t listener) const {
    return hybrid_ ? hybrid_->earlyCounts(listener) : whole_.counts(listener);
  }
  const Simulation& simulation() const { return *simulation_; }
  /// Simulation::recordSurfaces. Control thread before the first frame, or the propagation
  /// thread between frames.
  void recordSurfaces(bool on) { simulation_->recordSurfaces(on); }
  /// Plays the sources that stand at their baked positions from `bake` (runtime/
  /// baked_playback.h): interpolated late response, live direct sound. The bake must be of this
  /// stage's scene (bake/bake_loader.h checks); nullptr detaches it. A bake carrying the wave
  /// band (BakedField::hasWave, loaded when the scene's wave.enabled) joins each baked pair's
  /// IR with the probes' wave bands blended with the late response's weights (the probes the
  /// source's grid reached, weights renormalised over them) by wave/wave_join.h, in place of
  /// any attachWaveBands set; throws as
  /// checkWaveBandsAllowed then, and InputError(bake file, "wave/band") for a band stored at
  /// another sample rate than the scene's. Control thread, between frames; allocates.
  void attachBake(std::shared_ptr<const BakedField> bake, BakeInterpolation settings = {});
  /// Throws InputError(scene file, "wave.enabled") in hybrid rendering (a source's IR is
  /// split there; the wave band needs it whole): a caller checks before simulating the bands.
  void checkWaveBandsAllowed() const;
  /// Joins each listener-source pair's wave band (wave/wave_join.h) to every IR synthesised
  /// for it from now on; nullptr detaches. Throws as checkWaveBandsAllowed. Control thread,
  /// between frames.
  void attachWaveBands(std::shared_ptr<const wave::WaveBandSet> bands);
  /// The attached bake's playback and counts, or nullptr.
  const BakedPlayback* bakedPlayback() const { return baked_.get(); }
  /// The per-source IRs listener l's last prepared set holds, one per source (in hybrid
  /// rendering the early parts only: wholeIrs() gives what each source is heard with).
  const std::vector<ImpulseResponse>& lastIrs(size_t listener = 0) const {
    return irs_.at(listener);
  }
  /// Every source's whole IR as listener l's last prepared set renders it, full IR length:
  /// lastIrs(l) itself, or in hybrid rendering each source's early part plus its late gain
  /// times its bus's late IR. Any thread that may read lastIrs(l); allocates the copy.
  std::vector<ImpulseResponse> wholeIrs(size_t listener = 0) const;
  /// The same written into `out`, whose IRs keep their capacity: once `out` has grown to the
  /// IRs' sizes, a call allocates nothing (the live snapshot's copy every frame).
  void wholeIrsInto(size_t listener, std::vector<ImpulseResponse>& out) const;
  /// The late buses' IRs listener l's last prepared set holds, one per bus (hybrid).
  const std::vector<ImpulseResponse>& lastLateIrs(size_t listener = 0) const {
    return lateIrs_.at(listener);
  }
  int numOutputs() const { return numOutputs_; }
  /// Samples of each per-source IR (the early part's in hybrid rendering).
  size_t irSamples() const { return irSamples_; }

  /// Wall seconds summed over frames: tracing passes, the pairs' finishing with the cache
  /// pool (Simulation::FrameTimes), IR synthesis, the convolver's partitions.
  struct Totals {
    uint64_t frames = 0, rays = 0, segments = 0;
    double traceSeconds = 0.0, pairsSeconds = 0.0, synthesisSeconds = 0.0, prepareSeconds = 0.0;
  };
  const Totals& totals() const { return totals_; }
  /// Each frame's stages (runtime/frame_profile.h): trace, pairs, synthesis and partition
  /// recorded here; the live session adds publish, snapshot and the whole frame. Written by
  /// the thread that runs the frames; snapshot() from any thread.
  FrameProfile& profile() { return *profile_; }
  const FrameProfile& profile() const { return *profile_; }

 private:
  /// The per-source synthesisers (none for mono output in hybrid rendering) and irSamples_.
  void makeSynthesizers(const PropagationSettings& settings, bool hybrid,
                        IrSynthesizer::Build build);
  /// The early part's length when the scene renders hybrid (runtime/hybrid_synthesis.h) and
  /// that is shorter than the IR, else 0.
  double hybridEarlySeconds(const PropagationSettings& settings) const;
  /// hybrid_, lateLayout_ and irSamples_ (the early part's) for hybrid rendering.
  void makeHybrid(const PropagationSettings& settings, double earlySeconds,
                  audio::ConvolverLayout::Planning planning, IrSynthesizer::Build build);
  /// The frame's inputs (inputs_) from the world, the bake's skipped pairs and the rays.
  void frameInputs(const WorldState& world, int raysPerEmitter);
  /// The frame's times into totals_ and the profile.
  void recordFrameTimes(const Simulation::FrameTimes& t);
  /// Hybrid: listener l's early parts, late buses' IRs and late gains and buses.
  void synthesizeHybrid(size_t listener);
  /// A set of this stage's layouts, sources and buses (makeExchange's factory).
  std::unique_ptr<IrSet> makeIrSet() const;
  /// Runs work on the simulation's tracing threads (forEachParallel).
  SpatialIrSynthesizer::ParallelFor onTracingThreads();
  /// Lets synth level its channels on the simulation's tracing threads.
  void levelOnTracingThreads(SpatialIrSynthesizer& synth);
  /// Synthesises source s's IR for listener l into irs_[l][s] with group g's workspace.
  void synthesize(size_t s, size_t listener, size_t g);
  /// Joins the wave band of pair (s, listener) to its IR `ir`: the bake's (its probes blended)
  /// when the pair plays from a bake that carries one, else attachWaveBands's, else none.
  void joinWave(size_t s, size_t listener, ImpulseResponse& ir);
  /// Every source's IR (rendered whole) in the source groups on the tracing threads; in one
  /// group, on this thread, while a bake or wave bands are attached (their reads are serial).
  void synthesizeSources(size_t listener);
  /// Listener l's IRs (and late buses') partitioned and transformed into set, in groups on
  /// the tracing threads (each IR independent, each group with the set's scratch of its own).
  void partition(size_t listener, IrSet& set);

  std::shared_ptr<const SceneDesc> scene_;
  int numOutputs_;
  /// Sources rendered whole are synthesised in this many groups (at most the tracing
  /// threads): source s with group s % groups's workspace, so the IRs do not depend on it.
  size_t sourceGroups_ = 1;
  /// Per source group: one source's IR channels, numOutputs_ pointers.
  std::vector<std::vector<float*>> channelScratch_;
  /// partition()'s groups (the tracing threads): per group, numOutputs_ channel pointers.
  std::vector<std::vector<const float*>> partitionChannels_;
  std::unique_ptr<Simulation> simulation_;
  std::vector<std::unique_ptr<IrSynthesizer>> synthesizers_;  ///< mono: one per source
  std::unique_ptr<SpatialIrSynthesizer> spatial_;             ///< stereo / binaural
  /// Spatial output rendered whole: workspace copies of spatial_ for source groups 1, 2, ...
  std::vector<std::unique_ptr<SpatialIrSynthesizer>> spatialCopies_;
  std::unique_ptr<BakedPlayback> baked_;                      ///< attachBake, or none
  std::shared_ptr<const wave::WaveBandSet> waveBands_;         ///< attachWaveBands, or none
  /// The bake's wave bands, "listener" = probe: [probe][source] (attachBake), or none.
  std::unique_ptr<const wave::WaveBandSet> bakedWave_;
  std::vector<wave::BandWeight> waveBlend_;  ///< joinWave's scratch, reserved by attachBake
  std::unique_ptr<HybridSynthesis> hybrid_;                   ///< hybrid rendering, or none
  KeptIrs whole_;  ///< sources rendered whole: their IRs kept (reuseSourceIrs)
  std::shared_ptr<const audio::NonUniformLayout> layout_;
  std::shared_ptr<const audio::NonUniformLayout> lateLayout_;  ///< hybrid: full-length IRs
  std::vector<std::vector<ImpulseResponse>> irs_;      ///< [listener][source]
  std::vector<std::vector<ImpulseResponse>> lateIrs_;  ///< [listener][bus]
  std::vector<glm::vec3> sources_;  ///< traceWorld's source positions
  /// Hybrid: per listener, the last prepared set's late gain and bus of each source.
  std::vector<std::vector<float>> lastGain_;
  std::vector<std::vector<int>> lastBus_;
  FrameInputs inputs_;  ///< the last traceWorld's, reused from frame to frame
  double lastTime_ = 0.0;                ///< scene time of the last traced frame
  size_t irSamples_ = 0;
  Totals totals_;
  std::unique_ptr<FrameProfile> profile_ = std::make_unique<FrameProfile>();
};

}  // namespace dpc
