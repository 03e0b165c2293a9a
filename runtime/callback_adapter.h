// CallbackAdapter: the FIFO between a host's audio callbacks (any size from 1 to
// kMaxCallbackFrames frames, varying from call to call) and the engine's fixed blocks of
// blockSize frames. Each host frame takes the output of the previous engine block at the same
// position and leaves its input there; a block is rendered as soon as it is full, before its
// output slot is read again. So the delay is exactly one block (latencyFrames()) whatever the
// call sizes: output sample t (counted from the first call) is engine output sample
// t - blockSize (zeros before), and host input sample t reaches the engine's block holding t.
// Construction allocates (control thread); run() runs on the audio thread and never
// allocates, locks, throws or waits.
#pragma once

#include <algorithm>
#include <cassert>
#include <vector>

namespace dpc {

/// The engine block for a host that calls with `hostFrames` frames each time (a JACK period, an
/// LV2 nominal block length): the same, within audio.block_size's limits, so that every call
/// renders one block and the work per call is even (a larger block would be rendered whole by
/// one call in several: bursts). Any thread; no allocation.
int engineBlockForHostPeriod(int hostFrames);

class CallbackAdapter {
 public:
  /// Largest host call run() accepts, frames.
  static constexpr int kMaxCallbackFrames = 8192;

  /// blockSize: engine block (frames, >= 1); sources: host input channels (one per scene
  /// source); channels: output channels. Control thread; allocates.
  CallbackAdapter(int blockSize, int sources, int channels);

  /// Audio thread. Moves `frames` (1..kMaxCallbackFrames) frames through the FIFO: inputs
  /// (nullptr: none; else inputs[s][0..frames) for s < sourceCount()) in, outputs[c][0..frames)
  /// for c < channels() out. Whenever a block is full it calls
  /// renderBlock(blockInputs, blockOutputs), which must fill blockOutputs[c][0..blockSize)
  /// from blockInputs (nullptr when this call has no host inputs) and return whether it
  /// swapped IRs. Returns whether any block it rendered swapped.
  template <class RenderBlock>
  bool run(const float* const* inputs, float* const* outputs, int frames,
           RenderBlock&& renderBlock) noexcept {
    assert(frames >= 1 && frames <= kMaxCallbackFrames);
    bool swapped = false;
    for (int done = 0; done < frames;) {
      const int k = std::min(frames - done, blockSize_ - fill_);
      if (inputs)
        for (size_t s = 0; s < in_.size(); ++s)
          std::copy(inputs[s] + done, inputs[s] + done + k, in_[s].data() + fill_);
      for (size_t c = 0; c < out_.size(); ++c)
        std::copy(out_[c].data() + fill_, out_[c].data() + fill_ + k, outputs[c] + done);
      fill_ += k;
      done += k;
      if (fill_ == blockSize_) {
        swapped = renderBlock(inputs ? inPtr_.data() : nullptr, outPtr_.data()) || swapped;
        fill_ = 0;
      }
    }
    return swapped;
  }

  /// Latency the FIFO adds, frames (constant: one engine block).
  int latencyFrames() const { return blockSize_; }
  int blockSize() const { return blockSize_; }
  /// Host input channels run() expects when it gets inputs.
  int sourceCount() const { return int(in_.size()); }
  int channels() const { return int(out_.size()); }

 private:
  int blockSize_;
  int fill_ = 0;                        ///< frames of the current block filled so far
  std::vector<std::vector<float>> in_;  ///< the host's inputs of the block being filled
  std::vector<const float*> inPtr_;
  std::vector<std::vector<float>> out_;  ///< the last engine block, read out while the next fills
  std::vector<float*> outPtr_;
};

}  // namespace dpc
