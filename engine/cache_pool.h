// CachePool: one memory budget shared by every diffuse path cache of a simulation (all
// source-listener pairs). A cache starts with small tables and grows them (doubling) as its
// paths need room; each growth takes its bytes from the pool, and when the pool cannot give
// them the cache merges its oldest entries into its coarse store instead (energy kept, delay
// resolution lost; engine/path_cache.h). So memory is committed as pairs use it, a pair with
// many paths may use more than an even share while others need less, and the whole engine
// stays within one budget. Refusals are counted (refusals()) and reported.
//
// Threads: tryReserve and release may be called concurrently from the tracing threads (caches of
// different pairs update in parallel); lock-free (one atomic counter). No allocation. No errors.
// Known defect: once the pool is full, which cache's growth is refused depends on the order in
// which the threads ask, so a render that fills the pool (the shipped market: 64 sources) is
// not the same from run to run with more than one tracing thread.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>

namespace dpc {

class CachePool {
 public:
  /// budgetBytes: the most bytes all caches' tables may hold together.
  explicit CachePool(size_t budgetBytes) : budget_(budgetBytes) {}
  CachePool(const CachePool&) = delete;
  CachePool& operator=(const CachePool&) = delete;

  /// Takes `bytes` from the pool: true when they fit within the budget; false (counted, nothing
  /// taken) otherwise.
  bool tryReserve(size_t bytes) {
    size_t used = used_.load(std::memory_order_relaxed);
    do {
      if (bytes > budget_ || used > budget_ - bytes) {
        refusals_.fetch_add(1, std::memory_order_relaxed);
        return false;
      }
    } while (!used_.compare_exchange_weak(used, used + bytes, std::memory_order_relaxed));
    return true;
  }
  /// Takes `bytes` whatever the budget (a cache's first tables: every pair gets at least those).
  void reserveAlways(size_t bytes) { used_.fetch_add(bytes, std::memory_order_relaxed); }
  /// Gives back bytes taken before.
  void release(size_t bytes) { used_.fetch_sub(bytes, std::memory_order_relaxed); }

  size_t budgetBytes() const { return budget_; }
  /// Bytes held by all caches' tables now.
  size_t usedBytes() const { return used_.load(std::memory_order_relaxed); }
  /// Growths refused because the pool was full (the cache merged instead), since construction.
  uint64_t refusals() const { return refusals_.load(std::memory_order_relaxed); }

 private:
  size_t budget_;
  std::atomic<size_t> used_{0};
  std::atomic<uint64_t> refusals_{0};
};

}  // namespace dpc
