#include "audio/limiter.h"

#include <algorithm>
#include <cmath>

namespace dpc::audio {

Limiter::Limiter(int sampleRate, float ceiling, float releaseSeconds)
    : ceiling_(ceiling),
      release_(float(1.0 - std::exp(-1.0 / (double(releaseSeconds) * double(sampleRate))))) {}

void Limiter::process(float* const* channels, int numChannels, size_t frames) noexcept {
  uint64_t limited = 0, over = 0;
  float g = gain_;
  float minGain = minGain_;
  for (size_t i = 0; i < frames; ++i) {
    float peak = 0.f;
    for (int c = 0; c < numChannels; ++c) peak = std::max(peak, std::abs(channels[c][i]));
    // Release toward 1, then clamp so this frame lands at the ceiling at most.
    g += (1.f - g) * release_;
    if (peak > ceiling_) {
      ++over;
      // One float step below the exact ratio, so that x * g cannot round above the ceiling.
      g = std::min(g, std::nextafter(ceiling_ / peak, 0.f));
    }
    if (g < 1.f) {
      ++limited;
      minGain = std::min(minGain, g);
      for (int c = 0; c < numChannels; ++c) channels[c][i] *= g;
    }
    // Rounding: a released gain a hair below 1 counts as 1 once inaudibly close.
    if (g > 1.f - 1e-6f) g = 1.f;
  }
  gain_ = g;
  if (limited) limitedFrames_.fetch_add(limited, std::memory_order_relaxed);
  if (over) overFrames_.fetch_add(over, std::memory_order_relaxed);
  if (minGain < minGain_) {
    minGain_ = minGain;
    maxReductionDb_.store(-20.f * std::log10(minGain), std::memory_order_relaxed);
  }
}

}  // namespace dpc::audio
