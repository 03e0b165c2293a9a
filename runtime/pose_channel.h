// PoseChannel: the listener pose, written by the control thread and read by the propagation
// thread without locks (a sequence lock; Boehm, "Can seqlocks get along with programming
// language memory models?", MSPC 2012: data held in relaxed atomics, so it is race-free in the
// C++ memory model and clean under ThreadSanitizer).
// publish(): one writer thread at a time; wait-free; no allocation. read(): any thread;
// lock-free (retries while a write is in progress); no allocation. No errors.
#pragma once

#include <atomic>
#include <cstdint>
#include <cstring>
#include <glm/vec3.hpp>

namespace dpc {

struct ListenerPose {
  glm::vec3 position{0.f};    ///< metres
  float yawRadians = 0.f;     ///< heading about the up axis (0 = +x, + = left), radians
  float pitchRadians = 0.f;   ///< above the horizon, radians
  int64_t publishedNs = 0;    ///< steady_clock time of publication, ns (for latency)
  double sceneSeconds = 0.0;  ///< scene time the pose belongs to (trajectory time)
};

class PoseChannel {
 public:
  void publish(const ListenerPose& pose) {
    Words w{};
    std::memcpy(w.data, &pose, sizeof(ListenerPose));
    const uint32_t s = seq_.load(std::memory_order_relaxed);
    seq_.store(s + 1, std::memory_order_relaxed);  // odd: write in progress
    std::atomic_thread_fence(std::memory_order_release);
    for (size_t i = 0; i < kWords; ++i) words_[i].store(w.data[i], std::memory_order_relaxed);
    seq_.store(s + 2, std::memory_order_release);
  }

  ListenerPose read() const {
    Words w{};
    for (;;) {
      const uint32_t s0 = seq_.load(std::memory_order_acquire);
      if (s0 & 1u) continue;
      for (size_t i = 0; i < kWords; ++i) w.data[i] = words_[i].load(std::memory_order_relaxed);
      std::atomic_thread_fence(std::memory_order_acquire);
      if (seq_.load(std::memory_order_relaxed) == s0) break;
    }
    ListenerPose p;
    std::memcpy(&p, w.data, sizeof(ListenerPose));
    return p;
  }

 private:
  static constexpr size_t kWords = (sizeof(ListenerPose) + 7) / 8;
  struct Words {
    uint64_t data[kWords];
  };
  std::atomic<uint32_t> seq_{0};
  std::atomic<uint64_t> words_[kWords] = {};
};

}  // namespace dpc
