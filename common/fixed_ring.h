// FixedRing<T>: the one fixed-capacity FIFO of dpc, for hand-overs between two threads (IR sets
// from the propagation thread to the audio thread and back, recorded samples from the audio
// thread to the recorder) and for FIFOs inside one thread (a convolver's retired IRs, an audio
// stage's spent IR sets).
//
// Single producer, single consumer: one thread pushes (it owns tail_), one thread pops (it owns
// head_); they may be the same thread. The producer reads head_ with acquire and publishes
// tail_ with release; the consumer the other way round; the two indices sit on separate cache
// lines. Capacity is fixed at construction (the only allocation); tryPush/tryPop and the bulk
// forms are wait-free, never allocate, lock, throw or make system calls. A push into a full
// ring is refused and counted (overflows()): a caller that keeps going reports the count.
// T must be trivially copyable (pointers, samples).
#pragma once

#include <atomic>
#include <cassert>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <type_traits>

namespace dpc {

template <class T>
class FixedRing {
  static_assert(std::is_trivially_copyable_v<T>);

 public:
  /// Room for `capacity` elements (>= 1). Any thread, before the ring is shared. Allocates.
  explicit FixedRing(size_t capacity)
      : capacity_(capacity), slots_(std::make_unique<T[]>(capacity + 1)) {
    assert(capacity >= 1);
  }
  FixedRing(const FixedRing&) = delete;
  FixedRing& operator=(const FixedRing&) = delete;

  /// Producer: appends v; false (and counted in overflows()) when the ring is full.
  bool tryPush(const T& v) noexcept { return pushBulk(&v, 1) == 1; }
  /// Consumer: takes the oldest element into out; false when the ring is empty.
  bool tryPop(T& out) noexcept { return popBulk(&out, 1) == 1; }

  /// Producer: appends as many of v[0..n) as fit, in order; returns how many. Elements that do
  /// not fit are counted in overflows().
  size_t pushBulk(const T* v, size_t n) noexcept {
    const size_t tail = tail_.load(std::memory_order_relaxed);
    const size_t head = head_.load(std::memory_order_acquire);
    const size_t k = n < free(head, tail) ? n : free(head, tail);
    for (size_t i = 0; i < k; ++i) slots_[wrap(tail + i)] = v[i];
    tail_.store(wrap(tail + k), std::memory_order_release);
    if (k < n) overflows_.fetch_add(n - k, std::memory_order_relaxed);
    return k;
  }
  /// Consumer: moves up to n of the oldest elements into out[0..); returns how many.
  size_t popBulk(T* out, size_t n) noexcept {
    const size_t head = head_.load(std::memory_order_relaxed);
    const size_t tail = tail_.load(std::memory_order_acquire);
    const size_t used = count(head, tail);
    const size_t k = n < used ? n : used;
    for (size_t i = 0; i < k; ++i) out[i] = slots_[wrap(head + i)];
    head_.store(wrap(head + k), std::memory_order_release);
    return k;
  }

  /// Elements waiting. Exact on either end's thread when the other is idle, otherwise a
  /// snapshot. Any thread.
  size_t size() const noexcept {
    return count(head_.load(std::memory_order_acquire), tail_.load(std::memory_order_acquire));
  }
  bool empty() const noexcept { return size() == 0; }
  size_t capacity() const noexcept { return capacity_; }
  /// Elements refused because the ring was full, since construction. Any thread (relaxed).
  uint64_t overflows() const noexcept { return overflows_.load(std::memory_order_relaxed); }

 private:
  // One slot stays empty so that head == tail means empty: slots_ holds capacity_ + 1.
  size_t wrap(size_t i) const noexcept { return i >= capacity_ + 1 ? i - (capacity_ + 1) : i; }
  size_t count(size_t head, size_t tail) const noexcept {
    return tail >= head ? tail - head : tail + capacity_ + 1 - head;
  }
  size_t free(size_t head, size_t tail) const noexcept { return capacity_ - count(head, tail); }

  const size_t capacity_;
  std::unique_ptr<T[]> slots_;
  alignas(64) std::atomic<size_t> head_{0};  ///< consumer's index
  alignas(64) std::atomic<size_t> tail_{0};  ///< producer's index
  alignas(64) std::atomic<uint64_t> overflows_{0};
};

}  // namespace dpc
