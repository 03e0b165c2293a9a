// AudioStage: the audio side of the render pipeline (runtime/render_pipeline.h): the
// convolver of all sources and the dry signals' read position. Construction allocates
// (control thread); offer(), process() and takeSpent() run on the audio thread and never
// allocate, lock, log, throw or wait.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "audio/head_tracked_binaural.h"
#include "audio/late_bus_mixer.h"
#include "audio/nonuniform_convolver.h"
#include "common/fixed_ring.h"
#include "runtime/dry_signals.h"
#include "runtime/propagation_stage.h"
#include "scene/orientation.h"

namespace dpc {

class AudioStage {
 public:
  /// layout: the propagation stage's (PropagationStage::layout()); dry: the signals played
  /// when process() gets no host inputs (one per scene source); numOutputs: IR channels.
  /// Hybrid rendering (runtime/hybrid_synthesis.h): lateLayout and lateBuses > 0 from
  /// PropagationStage::lateLayout()/lateBuses(); every set offered then carries late IRs.
  AudioStage(std::shared_ptr<const audio::NonUniformLayout> layout,
             std::shared_ptr<const DrySignals> dry, int numOutputs,
             std::shared_ptr<const audio::NonUniformLayout> lateLayout = nullptr,
             int lateBuses = 0);
  /// The stage for `propagation`'s layouts and outputs; for head-tracked binaural output
  /// (OutputFormat::kAmbisonicBinaural) with the decoder of the scene's HRTF. Control thread;
  /// allocates; throws InputError naming audio.hrtf for an unreadable SOFA file.
  AudioStage(const PropagationStage& propagation, std::shared_ptr<const DrySignals> dry);
  ~AudioStage();

  /// Channels process() writes: the IR channels, or 2 (ears) for head-tracked binaural.
  int renderedChannels() const { return head_ ? 2 : numOutputs_; }
  /// Head-tracked binaural: the listener's head orientation from the next block on (the sound
  /// field turns with a one-block crossfade when it changed). Ignored for other outputs.
  /// Audio thread; no allocation.
  void setHeadOrientation(const Orientation& head);

  /// Schedules a new IR set for the next block (newest wins: a set offered while another is
  /// still pending is returned through takeSpent()). Audio thread.
  void offer(IrSet* set);
  /// Renders one block of layout.blockSize() frames into out[c] (renderedChannels()).
  /// inputs: nullptr reads the scene's dry signals from the current position (silence past
  /// their end); otherwise inputs[s][0..blockSize) is source s's dry block (one per scene
  /// source, as given by a host: gain applied, unusable samples replaced, see readHostInput).
  /// Audio thread.
  void process(float* const* out, const float* const* inputs = nullptr);
  /// Sources (one dry input each).
  int sourceCount() const { return convolver_.numSources(); }
  /// A set no longer in use (superseded before it was applied, or no partition level uses it
  /// any more), or nullptr. Audio thread; the caller returns it to the propagation side.
  IrSet* takeSpent();

  /// The newest set applied (every level takes it at its next chunk), or nullptr. This and
  /// the two counters below: the audio thread.
  const IrSet* current() const { return current_; }
  uint64_t blocksProcessed() const { return blocks_; }
  /// IR sets applied (crossfades started).
  uint64_t irsApplied() const { return applied_; }
  /// Host input samples replaced by 0 since the start: not finite, or beyond
  /// +-kMaxSignalMagnitude.
  uint64_t replacedInputSamples() const { return replacedInputSamples_; }
  /// IR sets that found the spent ring full (takeSpent() not drained): they never return to
  /// the pool. Any thread (relaxed); 0 when the caller drains takeSpent() after every block.
  uint64_t lostSets() const { return spent_.overflows(); }
  /// Partitions the convolvers left out because a response's onset jumped past their skipped
  /// transforms (NonUniformConvolver::stalePartitions; early parts and late buses). Any thread.
  uint64_t stalePartitions() const;
  /// Whether the convolvers skip the forward FFTs of levels a source is silent at (default
  /// on: live, where the callback's time is what matters). Off, the convolution is exact
  /// whatever the responses do (a teleport leaves no partition out): offline renders. Control
  /// thread, before the first process(); no allocation.
  void setSkipSilentLevels(bool skip);
  /// Spreads IR swaps over `blocks` >= 1 blocks across source groups (NonUniformConvolver
  /// "Staggered swaps"; default 1: every source swaps in one block): a swap's extra
  /// multiply-accumulates fall in several blocks instead of one, and a source group hears its
  /// new IR up to blocks - 1 blocks later. Control thread, before the first process(); no
  /// allocation. Throws std::invalid_argument if blocks < 1.
  void setIrSwapSpread(int blocks);
  /// Blocks over which a swap is really spread: a set applied in block k reaches every source
  /// by block k + irSwapSpreadBlocks() - 1 (at most the blocks asked for; 1 when the groups
  /// collapse, e.g. a single source).
  int irSwapSpreadBlocks() const { return swapSpreadBlocks_; }

 private:
  /// Hands the pending set to the convolver if it has room.
  void applyPending();
  /// Points in_[s] at source s's dry block for this block.
  void readDry(size_t s, size_t blockSize);
  /// Points in_[s] at a copy of the host's block x[0..blockSize) for source s: the source's
  /// gain applied, a sample that is not finite or beyond +-kMaxSignalMagnitude (the limit of a
  /// file's signal) replaced by 0 and counted.
  void readHostInput(size_t s, size_t blockSize, const float* x);
  /// Moves the sets the convolvers retired into the spent ring (a hybrid set once both
  /// convolvers have retired it).
  void collectRetired();
  /// Marks the in-flight set holding `retired` (early or late part) retired by one convolver.
  void retire(const audio::NonUniformIrSet* retired, bool late);

  std::shared_ptr<const audio::NonUniformLayout> layout_;
  std::shared_ptr<const DrySignals> dry_;
  int numOutputs_;
  audio::NonUniformConvolver convolver_;
  int swapSpreadBlocks_ = 1;  ///< derived in setIrSwapSpread from the convolvers' groups
  std::shared_ptr<const audio::NonUniformLayout> lateLayout_;
  std::unique_ptr<audio::NonUniformConvolver> lateConvolver_;  ///< hybrid: the late buses
  std::unique_ptr<audio::LateBusMixer> lateMixer_;             ///< hybrid: their inputs
  /// Head-tracked binaural: the rotation and decoder, the Ambisonic block it reads (IR
  /// channels x block) and the head orientation last applied.
  std::unique_ptr<audio::HeadTrackedBinaural> head_;
  std::vector<float> ambisonic_;
  std::vector<float*> ambisonicChannels_;
  Orientation headOrientation_{};
  std::vector<float> tail_;       ///< per source one block: a partial or looped block, zero-padded
  std::vector<const float*> in_;  ///< per source: this block's dry input
  IrSet* current_ = nullptr;
  IrSet* pending_ = nullptr;
  /// Sets handed to the convolver and not yet retired (to map its spectra back to the set).
  static constexpr int kInFlightCapacity = audio::NonUniformConvolver::kRetiredCapacity;
  struct InFlight {
    IrSet* set = nullptr;
    bool early = false, late = false;  ///< retired by the per-source / late convolver
  };
  InFlight inFlight_[kInFlightCapacity] = {};
  static constexpr int kSpentCapacity = audio::NonUniformConvolver::kRetiredCapacity + 2;
  FixedRing<IrSet*> spent_{kSpentCapacity};  ///< sets for takeSpent(), oldest first
  size_t position_ = 0;
  uint64_t blocks_ = 0, applied_ = 0;
  uint64_t replacedInputSamples_ = 0;
};

}  // namespace dpc
