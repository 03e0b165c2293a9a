// CachePool: one memory budget shared by every diffuse path cache of a simulation (all
// source-listener pairs). A cache starts with small tables and grows them (doubling) as its
// paths need room; each growth takes its bytes from the pool, and when the pool cannot give
// them the cache merges its oldest entries into its coarse store instead (energy kept, delay
// resolution lost; engine/path_cache.h). So memory is committed as pairs use it, a pair with
// many paths may use more than an even share while others need less, and the whole engine
// stays within one budget. Refusals are counted (refusals()) and reported.
//
// Determinism: within a frame, each cache may take at most its frame share, the pool's free
// bytes at the frame's start divided by the caches sharing it (beginFrame). What a cache is
// granted then depends on the pool at the frame's start and on its own requests only, never
// on the order in which the tracing threads ask, so a render that fills the pool is the same
// on any number of threads. The shares of a frame add up to at most the free bytes, so the
// budget holds; a cache needing more than a share grows over several frames (or merges).
//
// Threads: tryReserve and release may be called concurrently from the tracing threads (caches of
// different pairs update in parallel); lock-free (one atomic counter). beginFrame: the thread
// that runs the frames, between frames. No allocation. No errors.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>

namespace dpc {

class CachePool {
 public:
  /// One cache's takes within a frame (kept by the cache, reset when the frame changes).
  struct FrameTake {
    uint64_t frame = 0;
    size_t bytes = 0;
  };

  /// budgetBytes: the most bytes all caches' tables may hold together.
  explicit CachePool(size_t budgetBytes) : budget_(budgetBytes), share_(budgetBytes) {}
  CachePool(const CachePool&) = delete;
  CachePool& operator=(const CachePool&) = delete;

  /// Starts a frame in which `caches` caches (> 0) may grow: each may take at most
  /// (budget - bytes held now) / caches until the next call. Before the first call a cache may
  /// take up to the whole budget.
  void beginFrame(size_t caches) {
    const size_t used = std::min(used_.load(std::memory_order_relaxed), budget_);
    share_ = (budget_ - used) / std::max<size_t>(caches, 1);
    ++frame_;
  }

  /// Takes `bytes` from the pool for a cache whose takes this frame are `take`: true when they
  /// fit within its frame share and the budget; false (counted, nothing taken) otherwise.
  bool tryReserve(size_t bytes, FrameTake& take) {
    if (take.frame != frame_) take = {frame_, 0};
    if (bytes > share_ - std::min(take.bytes, share_)) {
      refusals_.fetch_add(1, std::memory_order_relaxed);
      return false;
    }
    size_t used = used_.load(std::memory_order_relaxed);
    do {
      if (bytes > budget_ || used > budget_ - bytes) {
        refusals_.fetch_add(1, std::memory_order_relaxed);
        return false;
      }
    } while (!used_.compare_exchange_weak(used, used + bytes, std::memory_order_relaxed));
    take.bytes += bytes;
    return true;
  }
  /// Takes `bytes` whatever the budget (a cache's first tables: every pair gets at least those).
  void reserveAlways(size_t bytes) { used_.fetch_add(bytes, std::memory_order_relaxed); }
  /// Gives back bytes taken before.
  void release(size_t bytes) { used_.fetch_sub(bytes, std::memory_order_relaxed); }

  size_t budgetBytes() const { return budget_; }
  /// Bytes held by all caches' tables now.
  size_t usedBytes() const { return used_.load(std::memory_order_relaxed); }
  /// Growths refused because the pool or the frame share was full (the cache merged instead),
  /// since construction.
  uint64_t refusals() const { return refusals_.load(std::memory_order_relaxed); }

 private:
  size_t budget_;
  size_t share_;  ///< the frame share (beginFrame)
  uint64_t frame_ = 0;
  std::atomic<size_t> used_{0};
  std::atomic<uint64_t> refusals_{0};
};

}  // namespace dpc
