#include "runtime/recorder.h"

#include <algorithm>
#include <cassert>
#include <chrono>

#include "audio/rt_check.h"

namespace dpc {

Recorder::Recorder(int sampleRate, int channels, double keepSeconds, int maxBlockFrames,
                   const std::string& path)
    : sampleRate_(sampleRate),
      channels_(channels),
      ring_(size_t(kRingSeconds * sampleRate) * size_t(channels)) {
  assert(channels >= 1 && maxBlockFrames >= 1);
  scratch_.assign(size_t(maxBlockFrames) * size_t(channels), 0.f);
  popped_.assign(size_t(0.05 * sampleRate) * size_t(channels), 0.f);
  recorded_.assign(size_t(channels), {});
  if (!path.empty()) {
    writer_ = std::make_unique<audio::WavStreamWriter>(path, sampleRate, channels);
    return;
  }
  for (auto& ch : recorded_) ch.reserve(size_t(keepSeconds * sampleRate));
}

Recorder::~Recorder() {
  stop();
}

void Recorder::start() {
  if (running_.exchange(true)) return;
  thread_ = std::thread([this] {
    audio::rt::setThreadRole(audio::rt::ThreadRole::kWorker);
    loop();
  });
}

void Recorder::stop() {
  if (!running_.exchange(false)) return;
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void Recorder::push(const float* const* planar, int frames) noexcept {
  const size_t C = size_t(channels_), n = size_t(frames);
  assert(n * C <= scratch_.size());
  for (size_t i = 0; i < n; ++i)
    for (size_t c = 0; c < C; ++c) scratch_[i * C + c] = planar[c][i];
  ring_.pushBulk(scratch_.data(), n * C);  // what does not fit is counted
}

void Recorder::drain() {
  size_t n;
  while ((n = ring_.popBulk(popped_.data(), popped_.size())) > 0)
    for (size_t i = 0; i < n; ++i) {
      recorded_[phase_].push_back(popped_[i]);
      phase_ = (phase_ + 1) % size_t(channels_);
    }
  if (writer_) writeRecorded();
}

void Recorder::writeRecorded() {
  size_t n = recorded_.front().size();
  for (const auto& ch : recorded_) n = std::min(n, ch.size());
  if (n == 0) return;
  std::vector<const float*> planar;
  for (const auto& ch : recorded_) planar.push_back(ch.data());
  try {
    writer_->write(planar.data(), n);
  } catch (...) {
    writeError_ = std::current_exception();
    writer_.reset();  // removes the temporary; later samples are dropped
  }
  for (auto& ch : recorded_) ch.erase(ch.begin(), ch.begin() + ptrdiff_t(n));
}

void Recorder::loop() {
  while (running_.load(std::memory_order_relaxed)) {
    drain();
    std::unique_lock<std::mutex> lock(wakeMutex_);
    wake_.wait_for(lock, std::chrono::milliseconds(10),
                   [this] { return !running_.load(std::memory_order_relaxed); });
  }
  drain();
}

size_t Recorder::commit() {
  if (writeError_) std::rethrow_exception(writeError_);
  if (!writer_ || running_.load()) return 0;
  const size_t frames = writer_->frames();
  writer_->commit();
  writer_.reset();
  return frames;
}

audio::AudioData Recorder::take() {
  audio::AudioData a;
  a.sampleRate = sampleRate_;
  if (running_.load() || writer_) return a;
  size_t n = recorded_.empty() ? 0 : recorded_.front().size();
  for (const auto& ch : recorded_) n = std::min(n, ch.size());
  for (auto& ch : recorded_) {
    ch.resize(n);
    a.channels.push_back(std::move(ch));
  }
  recorded_.clear();
  return a;
}

}  // namespace dpc
