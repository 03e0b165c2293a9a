// ImpulseResponse: one source's pressure impulse response as rendered for one listener:
// channels x samples at a sample rate, tagged with the source it belongs to and the
// propagation frame that produced it. The one type in which IRs travel between the IR
// synthesis, the IR hand-over to the audio side, the responses read by hosts (C API, Python)
// and the files written (WAV, SOFA).
//
// Storage is one contiguous block, channel-major: channel c's samples are
// data()[c * samples() .. (c + 1) * samples()). Values are sound pressure relative to the
// source's, on the scale of the design's energy convention (docs/design.md): a unit impulse
// through every band has energy 1.
//
// Threads: a plain value; whoever holds it may read or write it. resize() allocates only
// while the block grows beyond its capacity; copying into an IR of the same or a larger
// capacity (assignFrom) does not allocate.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace dpc {

class ImpulseResponse {
 public:
  ImpulseResponse() = default;
  /// channels >= 0 channels of `samples` zero samples each at sampleRate Hz.
  ImpulseResponse(int channels, size_t samples, double sampleRate)
      : channels_(channels), samples_(samples), sampleRate_(sampleRate),
        data_(size_t(channels) * samples, 0.f) {}

  int channels() const { return channels_; }
  /// Samples per channel.
  size_t samples() const { return samples_; }
  /// Hz.
  double sampleRate() const { return sampleRate_; }
  /// The source (scene order) this IR belongs to.
  size_t source = 0;
  /// The propagation frame (counted from 0) that produced it.
  uint64_t frame = 0;

  float* channel(int c) { return data_.data() + size_t(c) * samples_; }
  const float* channel(int c) const { return data_.data() + size_t(c) * samples_; }
  std::span<float> channelSpan(int c) { return {channel(c), samples_}; }
  std::span<const float> channelSpan(int c) const { return {channel(c), samples_}; }
  /// All channels, channel-major (channels() * samples() values).
  std::span<const float> data() const { return data_; }
  std::span<float> data() { return data_; }

  /// Re-shapes to channels x samples, every sample 0. Allocates only beyond the capacity.
  void resize(int channels, size_t samples, double sampleRate) {
    channels_ = channels;
    samples_ = samples;
    sampleRate_ = sampleRate;
    data_.assign(size_t(channels) * samples, 0.f);
  }
  /// Becomes a copy of `other` (shape, samples, tags); allocates only beyond the capacity.
  void assignFrom(const ImpulseResponse& other) {
    channels_ = other.channels_;
    samples_ = other.samples_;
    sampleRate_ = other.sampleRate_;
    source = other.source;
    frame = other.frame;
    data_.assign(other.data_.begin(), other.data_.end());
  }
  /// Channel c as its own vector (for callers that keep channels apart). Allocates.
  std::vector<float> channelCopy(int c) const {
    return std::vector<float>(channel(c), channel(c) + samples_);
  }

  /// Same shape, rate and samples (the tags are not compared).
  bool operator==(const ImpulseResponse& o) const {
    return channels_ == o.channels_ && samples_ == o.samples_ && sampleRate_ == o.sampleRate_ &&
           data_ == o.data_;
  }

 private:
  int channels_ = 0;
  size_t samples_ = 0;
  double sampleRate_ = 0.0;
  std::vector<float> data_;
};

}  // namespace dpc
