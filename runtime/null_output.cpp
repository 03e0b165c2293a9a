#include "runtime/null_output.h"

#include <chrono>

#include "audio/rt_check.h"

namespace dpc {

NullOutput::NullOutput(int sampleRate, int blockSize, int channels, audio::RenderCallback cb,
                       void* user)
    : sampleRate_(sampleRate),
      blockSize_(blockSize),
      channels_(channels),
      callback_(cb),
      user_(user) {
  buffers_.assign(size_t(channels), std::vector<float>(size_t(blockSize)));
  for (auto& b : buffers_) pointers_.push_back(b.data());
}

NullOutput::~NullOutput() {
  stop();
}

void NullOutput::start() {
  if (running_.exchange(true)) return;
  thread_ = std::thread([this] { loop(); });
}

void NullOutput::loop() {
  audio::rt::setThreadRole(audio::rt::ThreadRole::kAudio);
  const auto period = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(double(blockSize_) / sampleRate_));
  auto next = std::chrono::steady_clock::now();
  while (running_.load(std::memory_order_relaxed)) {
    const auto t0 = std::chrono::steady_clock::now();
    callback_(user_, pointers_.data(), blockSize_);
    const auto t1 = std::chrono::steady_clock::now();
    next += period;
    const bool late = t1 > next;  // the callback overran its block period
    stats_.record(uint64_t(std::chrono::duration_cast<std::chrono::nanoseconds>(t1 - t0).count()),
                  late);
    if (late)
      next = t1;
    else
      std::this_thread::sleep_until(next);
  }
}

void NullOutput::stop() {
  if (!running_.exchange(false)) return;
  if (thread_.joinable()) thread_.join();
}

}  // namespace dpc
