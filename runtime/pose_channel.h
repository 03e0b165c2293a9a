// SeqlockChannel<T>: one trivially copyable value (the listener pose, a host-set source
// position or object pose), written by the control thread and read by the propagation
// thread without locks (a sequence lock; Boehm, "Can seqlocks get along with programming
// language memory models?", MSPC 2012: data held in relaxed atomics, so it is race-free in the
// C++ memory model and clean under ThreadSanitizer).
// publish(): one writer thread at a time; wait-free; no allocation. read(): any thread;
// lock-free (retries while a write is in progress); no allocation. tryRead(): one attempt,
// wait-free (the audio thread's read). No errors.
#pragma once

// Under GCC's -fsanitize=thread every atomic_thread_fence draws -Wtsan ("not supported"):
// ThreadSanitizer does not model fences. The channel's data are relaxed atomics, so TSan sees
// no race on them either way; the warning is noise here and silenced.
#if defined(__SANITIZE_THREAD__) && defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wtsan"
#endif

#include <atomic>
#include <cstdint>
#include <cstring>
#include <glm/vec3.hpp>
#include <type_traits>

namespace dpc {

struct ListenerPose {
  glm::vec3 position{0.f};    ///< metres
  float yawRadians = 0.f;     ///< heading about the up axis (0 = +x, + = left), radians
  float pitchRadians = 0.f;   ///< above the horizon, radians
  float rollRadians = 0.f;    ///< about forward, radians (+ = the right ear down)
  int64_t publishedNs = 0;    ///< steady_clock time of publication, ns (for latency)
  double sceneSeconds = 0.0;  ///< scene time the pose belongs to (trajectory time)
  /// The host's interval between this listener's publications, ns: a moving average (the
  /// newest gap weighs 1/4; the first gap alone at the second publication; 0 at the first).
  /// The propagation thread aligns its frames to it (runtime/pose_sync.h).
  int64_t intervalNs = 0;
};

/// A source position set by the host (overrides the scene's trajectory once set).
struct HostSourcePosition {
  glm::vec3 position{0.f};  ///< metres
  uint32_t set = 0;         ///< 0: never set (the scene's trajectory applies)
};

/// A source orientation set by the host: its directivity's forward axis is R(q) * (+x).
struct HostSourceRotation {
  float rotation[4] = {0.f, 0.f, 0.f, 1.f};  ///< unit quaternion x, y, z, w (glTF order)
  uint32_t set = 0;                          ///< 0: never set (the scene's keyframes apply)
};

/// An object pose set by the host: world = R(q) * local + position, q = (x, y, z, w) unit.
struct HostObjectPose {
  glm::vec3 position{0.f};                   ///< metres
  float rotation[4] = {0.f, 0.f, 0.f, 1.f};  ///< quaternion x, y, z, w (glTF order)
  uint32_t set = 0;                          ///< 0: never set
};

template <class T>
class SeqlockChannel {
  static_assert(std::is_trivially_copyable_v<T>);

 public:
  void publish(const T& value) {
    Words w{};
    std::memcpy(w.data, &value, sizeof(T));
    const uint32_t s = seq_.load(std::memory_order_relaxed);
    seq_.store(s + 1, std::memory_order_relaxed);  // odd: write in progress
    std::atomic_thread_fence(std::memory_order_release);
    for (size_t i = 0; i < kWords; ++i) words_[i].store(w.data[i], std::memory_order_relaxed);
    seq_.store(s + 2, std::memory_order_release);
  }

  /// One attempt: true and the value in `out` unless a write was in progress (out unchanged).
  bool tryRead(T& out) const {
    Words w{};
    const uint32_t s0 = seq_.load(std::memory_order_acquire);
    if (s0 & 1u) return false;
    for (size_t i = 0; i < kWords; ++i) w.data[i] = words_[i].load(std::memory_order_relaxed);
    std::atomic_thread_fence(std::memory_order_acquire);
    if (seq_.load(std::memory_order_relaxed) != s0) return false;
    std::memcpy(&out, w.data, sizeof(T));
    return true;
  }

  T read() const {
    Words w{};
    for (;;) {
      const uint32_t s0 = seq_.load(std::memory_order_acquire);
      if (s0 & 1u) continue;
      for (size_t i = 0; i < kWords; ++i) w.data[i] = words_[i].load(std::memory_order_relaxed);
      std::atomic_thread_fence(std::memory_order_acquire);
      if (seq_.load(std::memory_order_relaxed) == s0) break;
    }
    T v;
    std::memcpy(&v, w.data, sizeof(T));
    return v;
  }

 private:
  static constexpr size_t kWords = (sizeof(T) + 7) / 8;
  struct Words {
    uint64_t data[kWords];
  };
  std::atomic<uint32_t> seq_{0};
  std::atomic<uint64_t> words_[kWords] = {};
};

using PoseChannel = SeqlockChannel<ListenerPose>;

}  // namespace dpc
