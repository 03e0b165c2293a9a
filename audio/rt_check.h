// Thread roles (docs/design.md "Thread roles"), recorded per thread so that debug builds can assert
// that a function runs where its documentation says ("Audio thread. Wait-free.").
//
// The role is a thread_local byte with constant initialisation: setting and reading it is a
// plain memory access (no allocation, no locks, no system calls), so it is safe on the audio
// thread. AudioOutput's PortAudio callback sets ThreadRole::kAudio on every callback; other
// threads set their role once when they start. The checks compile to nothing with NDEBUG
// (Release/RelWithDebInfo builds still record roles, which costs one store per callback).
//
// Heap calls on the audio thread are checked separately, by the interposing allocator of the
// real-time tests (tests/rt/alloc_counter.h).
#pragma once

#include <cassert>
#include <cstdint>

namespace dpc::audio::rt {

enum class ThreadRole : uint8_t {
  kUnknown = 0,  ///< not declared (e.g. a library's worker thread)
  kControl,      ///< main/UI: loads scenes, moves the listener, prints status
  kPropagation,  ///< traces rays, synthesises and prepares IRs; may allocate
  kAudio,        ///< renders blocks: never allocates, locks, logs, throws, waits or syscalls
  kWorker,       ///< below the audio thread (the recorder): never waited for by it
};

namespace detail {
// initial-exec: the byte sits in the static TLS block, so the first access on a thread is a
// plain memory access even inside a dlopen()ed library (a plugin host loading libdpc), where
// the default model would have glibc allocate the thread's block on that first access (the
// audio thread's first dpc_engine_process; tests/lv2/lv2_rt_test.cpp counts it).
__attribute__((tls_model("initial-exec"))) inline thread_local ThreadRole tThreadRole =
    ThreadRole::kUnknown;
}  // namespace detail

/// Declares the calling thread's role. Any thread (the audio thread too). No allocation.
inline void setThreadRole(ThreadRole role) noexcept {
  detail::tThreadRole = role;
}
/// The calling thread's declared role (kUnknown if never set). Any thread. No allocation.
inline ThreadRole threadRole() noexcept {
  return detail::tThreadRole;
}
/// Whether the calling thread declared itself the audio thread. Any thread. No allocation.
inline bool onAudioThread() noexcept {
  return detail::tThreadRole == ThreadRole::kAudio;
}

/// For audio-thread entry points that the host's thread calls (device callback, a host's
/// process call): declares the calling thread the audio thread. Debug builds assert that it
/// declared no other role before (a propagation or recorder thread must never render). Any
/// thread; no allocation.
inline void enterAudioThread() noexcept {
  assert(detail::tThreadRole == ThreadRole::kUnknown || detail::tThreadRole == ThreadRole::kAudio);
  detail::tThreadRole = ThreadRole::kAudio;
}

/// Declares the calling thread's role for the object's lifetime and restores the previous one
/// after: e.g. the offline renderer plays the audio thread around AudioStage::process. No
/// allocation.
class ScopedThreadRole {
 public:
  explicit ScopedThreadRole(ThreadRole role) noexcept : previous_(detail::tThreadRole) {
    detail::tThreadRole = role;
  }
  ~ScopedThreadRole() { detail::tThreadRole = previous_; }
  ScopedThreadRole(const ScopedThreadRole&) = delete;
  ScopedThreadRole& operator=(const ScopedThreadRole&) = delete;

 private:
  ThreadRole previous_;
};

}  // namespace dpc::audio::rt

/// Debug builds: aborts (assert) unless the calling thread declared ThreadRole::kAudio.
#define DPC_ASSERT_AUDIO_THREAD() assert(::dpc::audio::rt::onAudioThread())
/// Debug builds: aborts if the calling thread is the audio thread (for functions that may
/// allocate, lock or block). Threads with no declared role pass.
#define DPC_ASSERT_NOT_AUDIO_THREAD() assert(!::dpc::audio::rt::onAudioThread())
