// AudioStage: the audio side of the render pipeline (runtime/render_pipeline.h): the
// convolver of all sources and the dry signals' read position. It takes the newest IR set of
// its channel of an IrExchange (runtime/ir_exchange.h) when its convolvers can take one, and
// releases each set back once no convolver holds it. Construction allocates (control thread);
// process() runs on the audio thread and never allocates, locks, logs, throws or waits.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "audio/head_tracked_binaural.h"
#include "audio/late_bus_mixer.h"
#include "audio/nonuniform_convolver.h"
#include "runtime/dry_signals.h"
#include "runtime/ir_exchange.h"
#include "runtime/propagation_stage.h"

namespace dpc {

class AudioStage {
 public:
  /// layout: the propagation stage's (PropagationStage::layout()); dry: the signals played
  /// when process() gets no host inputs (one per scene source); numOutputs: IR channels.
  /// Hybrid rendering (runtime/hybrid_synthesis.h): lateLayout and lateBuses > 0 from
  /// PropagationStage::lateLayout()/lateBuses(); every set then carries late IRs. The sets
  /// come from `channel` of `exchange`, which must outlive the stage.
  AudioStage(std::shared_ptr<const audio::NonUniformLayout> layout,
             std::shared_ptr<const DrySignals> dry, int numOutputs, IrExchange& exchange,
             size_t channel, std::shared_ptr<const audio::NonUniformLayout> lateLayout = nullptr,
             int lateBuses = 0);
  /// The stage for `propagation`'s layouts and outputs; for head-tracked binaural output
  /// (OutputFormat::kAmbisonicBinaural) with the decoder of the scene's HRTF. Control thread;
  /// allocates; throws InputError naming audio.hrtf for an unreadable SOFA file.
  AudioStage(const PropagationStage& propagation, std::shared_ptr<const DrySignals> dry,
             IrExchange& exchange, size_t channel = 0);
  ~AudioStage();

  /// Channels process() writes: the IR channels, or 2 (ears) for head-tracked binaural.
  int renderedChannels() const { return head_ ? 2 : numOutputs_; }
  /// Head-tracked binaural: the listener's head orientation from the next block on (the sound
  /// field turns with a one-block crossfade when it changed). Ignored for other outputs.
  /// Audio thread; no allocation.
  void setHeadOrientation(const Orientation& head);

  /// Renders one block of layout.blockSize() frames into out[c] (renderedChannels()), first
  /// taking the exchange's newest set when the convolvers can take one.
  /// inputs: nullptr reads the scene's dry signals from the current position (silence past
  /// their end); otherwise inputs[s][0..blockSize) is source s's dry block (one per scene
  /// source, as given by a host: gain applied, unusable samples replaced, see readHostInput).
  /// Audio thread.
  void process(float* const* out, const float* const* inputs = nullptr);
  /// Sources (one dry input each).
  int sourceCount() const { return convolver_.numSources(); }
  /// The newest set applied (every level takes it at its next chunk), or nullptr. This and
  /// the two counters below: the audio thread.
  const IrSet* current() const { return current_; }
  uint64_t blocksProcessed() const { return blocks_; }
  /// IR sets applied (crossfades started).
  uint64_t irsApplied() const { return applied_; }
  /// Host input samples replaced by 0 since the start: not finite, or beyond
  /// +-kMaxSignalMagnitude.
  uint64_t replacedInputSamples() const { return replacedInputSamples_; }
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
  /// Hands the exchange's newest set to the convolvers if they have room for one.
  void applyNewest();
  /// Points in_[s] at source s's dry block for this block.
  void readDry(size_t s, size_t blockSize);
  /// Points in_[s] at a copy of the host's block x[0..blockSize) for source s: the source's
  /// gain applied, a sample that is not finite or beyond +-kMaxSignalMagnitude (the limit of a
  /// file's signal) replaced by 0 and counted.
  void readHostInput(size_t s, size_t blockSize, const float* x);
  /// Releases the sets the convolvers retired (a hybrid set once both have retired it).
  void collectRetired();
  /// One convolver retired `part` (the early or late part of a set).
  void retire(const audio::NonUniformIrSet* part, bool late);

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
  IrExchange& exchange_;
  size_t channel_;
  IrSet* current_ = nullptr;
  size_t position_ = 0;
  uint64_t blocks_ = 0, applied_ = 0;
  uint64_t replacedInputSamples_ = 0;
};

}  // namespace dpc
