// The rendering pipeline shared by offline (--offline) and live playback: only the clock
// differs between them.
//
//   PropagationStage (propagation thread)          AudioStage (audio thread)
//   listener pose -> Simulation frame -> energy    pops prepared IrSet, convolves every
//   responses -> pressure IRs -> non-uniform       source's dry signal (non-uniform partitions,
//   partition + FFT into a recycled IrSet          crossfade old/new IR at every partition
//                          ----- IrSet* ------>    level), mixes into the output bus
//                          <--- spent IrSet* ----
//
// IrSet: the partitioned spectra of every source's IR (numOutputs channels each) plus the frame
// it came from. Sets are allocated up front in a pool by the PropagationStage; the audio side
// only borrows them and hands each back once no partition level uses it.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "audio/nonuniform_convolver.h"
#include "audio/wav_io.h"
#include "common/fixed_ring.h"
#include "synthesis/ir_synthesis.h"
#include "scene/scene.h"
#include "engine/simulation.h"
#include "synthesis/spatial_ir.h"

namespace dpc {

/// Impulse responses of one propagation frame, partitioned and transformed, for all sources.
struct IrSet {
  std::unique_ptr<audio::NonUniformIrSet> irs;  ///< scene sources x output channels
  size_t listener = 0;           ///< listener index (scene.listeners order) it was computed for
  uint64_t frame = 0;            ///< propagation frame index that produced it
  double poseTimeSeconds = 0.0;  ///< scene time of the listener pose it was computed for
  int64_t poseNs = 0;            ///< live: steady_clock ns when that pose was published (latency)
  int64_t readyNs = 0;           ///< live: steady_clock ns when the set was ready (IR age)
};

/// Dry source signals at the output rate, mono, gain applied. Control thread; allocates;
/// throws InputError naming the scene file and sources[i].signal.
struct DrySignals {
  std::vector<std::vector<float>> samples;  ///< per source, at the scene's sample rate
  std::vector<char> loop;                   ///< per source: repeat the signal (SourceDesc::loop)
  std::vector<std::string> notes;           ///< e.g. "resampled 22050 -> 48000 Hz"
  /// Frames of the longest non-looping signal (of the longest signal if all loop).
  size_t longestFrames() const;
};
DrySignals loadDrySignals(const SceneDesc& scene);

/// IR channels for an output format: 1 for mono, 2 for stereo and binaural.
int outputChannels(OutputFormat format);

/// The spatial IR synthesiser for scene.audio.output (stereo: constant-power panning;
/// binaural: HRIRs from scene.audio.hrtfPath at the scene's rate) over
/// defaultSpatialDirections(). Control thread; allocates; throws InputError naming
/// audio.hrtf for an unreadable SOFA file.
std::unique_ptr<SpatialIrSynthesizer> makeSpatialSynthesizer(const SceneDesc& scene,
                                                             const PropagationSettings& settings,
                                                             double roomVolume);

/// Propagation thread side. Construction (control thread) builds the Embree scene, the IR
/// synthesisers (mono per source, or one spatial synthesiser with HRTF or panning filters
/// shared by all sources), the convolver layout and a pool of IrSets (poolSize plus two per
/// partition level beyond the first: a slow level keeps its old and new set through its
/// crossfade); allocates; throws
/// InputError (e.g. an unreadable SOFA file, named by the scene's audio.hrtf) or
/// std::runtime_error.
class PropagationStage {
 public:
  PropagationStage(const SceneDesc& scene, const PropagationSettings& settings, int poolSize = 4);

  /// Runs one frame for the listener at `listener` facing `orientation` (scene time t
  /// seconds), synthesises and prepares every source's IR into a free IrSet from the pool and
  /// returns it; nullptr if no set is free (all borrowed by the audio side). Propagation
  /// thread; allocates only while the cache's tables grow.
  IrSet* computeFrame(const glm::vec3& listener, const Orientation& orientation, double t);
  /// The same for a whole world state (docs/design.md, "World state"): every source and object
  /// where `world` puts them, the listener world.listener*[listener] (index must be valid:
  /// std::out_of_range otherwise). Host overrides are replaced for this frame.
  IrSet* computeFrame(const WorldState& world, size_t listener);
  /// Every listener in one pass (docs/dynamic.md, "Several listeners"): listener l at
  /// world.listener*[l] with the radius of scene.listeners[l] (scene.listener when the scene
  /// lists none); sources and objects where `world` puts them, except those a host overrode.
  /// Each source's rays are traced once and tested against all listener spheres; every
  /// source-listener pair has its own cache. Then prepare(l) makes listener l's IR set.
  /// Propagation thread; allocates only while tables grow (more listeners than before).
  void traceWorld(const WorldState& world);
  /// Synthesises listener l's IRs from the last traceWorld (or computeFrame: listener 0),
  /// partitions and transforms them into a free IrSet (set->listener = l) and returns it;
  /// nullptr if no set is free. l < listenerCount() (std::out_of_range otherwise).
  /// Propagation thread; no allocation.
  IrSet* prepare(size_t listener);
  /// Listeners the last frame traced.
  size_t listenerCount() const { return simulation_->listenerCount(); }
  /// Host overrides of the scene's trajectories for the following frames: source `index` at
  /// `position` (m), object `index` at `pose`. Out-of-range indices are ignored (callers check).
  /// Propagation thread; no allocation.
  void overrideSource(size_t index, const glm::vec3& position);
  void overrideObject(size_t index, const Pose& pose);
  /// Rays per source for the following frames (Simulation::setRaysPerFrame). Propagation
  /// thread, between frames.
  void setRaysPerFrame(int n) { simulation_->setRaysPerFrame(n); }
  /// Gives a set back to the pool. Propagation thread.
  void recycle(IrSet* set);

  const audio::NonUniformLayout& layout() const { return *layout_; }
  /// IrSets in the pool (fixed at construction).
  int poolSize() const { return int(pool_.size()); }
  const Simulation& simulation() const { return *simulation_; }
  /// The pressure IR listener l's last prepared set holds: [source][channel][sample].
  const std::vector<std::vector<std::vector<float>>>& lastIrs(size_t listener = 0) const {
    return irs_.at(listener);
  }
  int numOutputs() const { return numOutputs_; }
  size_t irSamples() const { return irSamples_; }

  struct Totals {
    uint64_t frames = 0, rays = 0, segments = 0;
    double traceSeconds = 0.0, synthesisSeconds = 0.0, prepareSeconds = 0.0;
  };
  const Totals& totals() const { return totals_; }

 private:
  /// Runs the frame with sourcePositions_ and objectPoses_ as they stand.
  IrSet* runPrepared(const glm::vec3& listener, const Orientation& orientation, double t);
  /// Traces `listeners` with sourcePositions_ and objectPoses_ as they stand (scene time t).
  void trace(std::span<const ListenerSphere> listeners, double t);

  const SceneDesc& scene_;
  std::vector<glm::vec3> sourcePositions_;  ///< this frame's, one per source (scene time t)
  std::vector<Pose> objectPoses_;           ///< this frame's, one per object
  std::vector<uint8_t> sourceOverridden_, objectOverridden_;  ///< host took over: 1
  int numOutputs_;
  std::unique_ptr<Simulation> simulation_;
  std::vector<std::unique_ptr<IrSynthesizer>> synthesizers_;  ///< mono: one per source
  std::unique_ptr<SpatialIrSynthesizer> spatial_;             ///< stereo / binaural
  std::unique_ptr<audio::NonUniformLayout> layout_;
  std::vector<std::unique_ptr<IrSet>> pool_;
  std::vector<IrSet*> free_;
  std::vector<std::vector<std::vector<std::vector<float>>>> irs_;  ///< [listener][source][ch]
  std::vector<ListenerSphere> spheres_;  ///< traceWorld's listener spheres
  double lastTime_ = 0.0;                ///< scene time of the last traced frame
  size_t irSamples_ = 0;
  Totals totals_;
};

/// Audio thread side: the convolver of all sources and the dry signals' read position. Construction
/// allocates (control thread); process() and offer() never allocate, lock, log, throw or wait.
class AudioStage {
 public:
  AudioStage(const audio::NonUniformLayout& layout, const DrySignals& dry, int numOutputs);

  /// Schedules a new IR set for the next block (newest wins: a set offered while another is
  /// still pending is returned through takeSpent()). Audio thread.
  void offer(IrSet* set);
  /// Renders one block of layout.blockSize() frames into out[c] (numOutputs channels).
  /// inputs: nullptr reads the scene's dry signals from the current position (silence past
  /// their end); otherwise inputs[s][0..blockSize) is source s's dry block (one per scene
  /// source, as given by a host). Audio thread.
  void process(float* const* out, const float* const* inputs = nullptr);
  /// Sources (one dry input each).
  int sourceCount() const { return convolver_.numSources(); }
  /// A set no longer in use (superseded before it was applied, or no partition level uses it
  /// any more), or nullptr. Audio thread; the caller returns it to the propagation side.
  IrSet* takeSpent();

  /// The newest set applied (every level takes it at its next chunk).
  const IrSet* current() const { return current_; }
  uint64_t blocksProcessed() const { return blocks_; }
  /// IR sets applied (crossfades started).
  uint64_t irsApplied() const { return applied_; }
  /// IR sets that found the spent ring full (takeSpent() not drained): they never return to
  /// the pool. Any thread (relaxed); 0 when the caller drains takeSpent() after every block.
  uint64_t lostSets() const { return spent_.overflows(); }

 private:
  const audio::NonUniformLayout& layout_;
  const DrySignals& dry_;
  int numOutputs_;
  audio::NonUniformConvolver convolver_;
  std::vector<float> tail_;       ///< per source one block: a partial or looped block, zero-padded
  std::vector<const float*> in_;  ///< per source: this block's dry input
  IrSet* current_ = nullptr;
  IrSet* pending_ = nullptr;
  /// Sets handed to the convolver and not yet retired (to map its spectra back to the set).
  static constexpr int kInFlightCapacity = audio::NonUniformConvolver::kRetiredCapacity;
  IrSet* inFlight_[kInFlightCapacity] = {};
  static constexpr int kSpentCapacity = audio::NonUniformConvolver::kRetiredCapacity + 2;
  FixedRing<IrSet*> spent_{kSpentCapacity};  ///< sets for takeSpent(), oldest first
  size_t position_ = 0;
  uint64_t blocks_ = 0, applied_ = 0;
};

}  // namespace dpc
