// Output safety limiter: the last stage before the device, so that it never receives a sample
// beyond full scale (a hot mix, a resonant room, a gain error). Peak limiter with instant
// attack and exponential release, the gain linked across channels so the stereo image stays:
// for each frame, g = min(g_released, ceiling / max_c |x_c|), where g_released recovers
// toward 1 with time constant `releaseSeconds`. Transparent (gain exactly 1) while the signal
// stays below the ceiling. No look-ahead: zero latency, at the cost of a hard knee on the
// sample that first exceeds the ceiling (it is a guard, not a mastering tool).
//
// Threads: process() on the audio thread only (no allocation, locks or system calls);
// the counters are relaxed atomics readable from any thread.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>

namespace dpc::audio {

class Limiter {
 public:
  /// sampleRate: Hz (> 0); ceiling: largest |sample| let through, linear (0, 1] (default
  /// 10^(-0.1/20), -0.1 dBFS, so that a 24-bit converter's rounding stays in range);
  /// releaseSeconds: time constant of the gain's return to 1 (> 0).
  explicit Limiter(int sampleRate, float ceiling = 0.98855f, float releaseSeconds = 0.05f);

  /// In place: channels[c][i], c < numChannels, i < frames. Audio thread.
  void process(float* const* channels, int numChannels, size_t frames) noexcept;

  /// Frames whose gain was below 1 (the limiter acted), since construction.
  uint64_t limitedFrames() const { return limitedFrames_.load(std::memory_order_relaxed); }
  /// Frames whose input exceeded the ceiling (they would have clipped at full scale or beyond).
  uint64_t overCeilingFrames() const { return overFrames_.load(std::memory_order_relaxed); }
  /// Largest gain reduction applied so far, dB (>= 0).
  float maxReductionDb() const { return maxReductionDb_.load(std::memory_order_relaxed); }
  float ceiling() const { return ceiling_; }

 private:
  float ceiling_;
  float release_;  ///< per-sample coefficient: g += (1 - g) * release_
  float gain_ = 1.f;
  float minGain_ = 1.f;
  std::atomic<uint64_t> limitedFrames_{0}, overFrames_{0};
  std::atomic<float> maxReductionDb_{0.f};
};

}  // namespace dpc::audio
