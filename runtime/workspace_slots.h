// WorkspaceSlots: hands the indices of a few workspaces to concurrent jobs, each index to one
// job at a time. Hybrid rendering synthesises every source's early part as a job of its own in
// whichever workspace is free, so that two threads share the frame's work evenly however it is
// split between sources and buses (a workspace holds nothing between syntheses, so the IRs do
// not depend on which one wrote them).
//
// Threads: any; acquire() and release() are lock-free (one atomic word). No allocation, no
// errors: with at least as many slots as jobs that run at once, acquire() finds one free
// without waiting (it yields the thread and retries otherwise).
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <thread>

namespace dpc {

class WorkspaceSlots {
 public:
  /// Slots the pool hands out, at most 64; all free. Not while any is held.
  void reset(size_t count) {
    count_ = count < 64 ? count : 64;
    busy_.store(0, std::memory_order_relaxed);
  }
  size_t count() const { return count_; }

  /// A free slot, now held by the caller until release().
  size_t acquire() {
    for (;;) {
      uint64_t busy = busy_.load(std::memory_order_relaxed);
      for (size_t i = 0; i < count_; ++i) {
        const uint64_t bit = uint64_t(1) << i;
        if ((busy & bit) == 0 &&
            busy_.compare_exchange_strong(busy, busy | bit, std::memory_order_acquire))
          return i;
      }
      std::this_thread::yield();
    }
  }
  void release(size_t slot) {
    busy_.fetch_and(~(uint64_t(1) << slot), std::memory_order_release);
  }

  /// Holds a slot for a scope.
  class Held {
   public:
    explicit Held(WorkspaceSlots& slots) : slots_(slots), slot_(slots.acquire()) {}
    ~Held() { slots_.release(slot_); }
    Held(const Held&) = delete;
    Held& operator=(const Held&) = delete;
    size_t slot() const { return slot_; }

   private:
    WorkspaceSlots& slots_;
    size_t slot_;
  };

 private:
  std::atomic<uint64_t> busy_{0};
  size_t count_ = 0;
};

}  // namespace dpc
