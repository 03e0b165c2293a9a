#include "apps/studio/studio_audio.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace dpc::studio {

StudioAudio::StudioAudio(int sampleRate, int channels)
    : sampleRate_(sampleRate),
      channels_(channels),
      capacity_(size_t(std::ceil(kHeldSeconds * std::max(sampleRate, 1)))) {
  if (sampleRate <= 0 || !playable(channels))
    throw std::invalid_argument("StudioAudio: a positive sample rate and 1 or 2 channels");
  ring_.assign(capacity_ * size_t(channels_), 0.f);
}

void StudioAudio::append(const float* const* channels, size_t frames) {
  std::lock_guard<std::mutex> lock(mutex_);
  const size_t C = size_t(channels_);
  for (size_t i = 0; i < frames; ++i) {
    float* slot = &ring_[((written_ + i) % capacity_) * C];
    for (size_t c = 0; c < C; ++c) slot[c] = channels[c][i];
  }
  written_ += frames;
}

StudioAudio::Chunk StudioAudio::since(uint64_t from) const {
  Chunk chunk;
  const size_t C = size_t(channels_);
  std::lock_guard<std::mutex> lock(mutex_);
  const uint64_t oldest = written_ > capacity_ ? written_ - capacity_ : 0;
  chunk.first = std::clamp(from, oldest, written_);
  chunk.skipped = chunk.first - std::min(from, chunk.first);
  const size_t frames = size_t(std::min<uint64_t>(written_ - chunk.first, kMaxChunkFrames));
  chunk.interleaved.resize(frames * C);
  for (size_t i = 0; i < frames; ++i) {
    const float* slot = &ring_[((chunk.first + i) % capacity_) * C];
    std::copy(slot, slot + C, &chunk.interleaved[i * C]);
  }
  return chunk;
}

}  // namespace dpc::studio
