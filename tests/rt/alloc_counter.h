// Heap-call counting for real-time tests: alloc_counter.cpp replaces malloc, calloc, realloc,
// free, aligned_alloc, posix_memalign, memalign, valloc, pvalloc and every global operator
// new/delete in the test executable (the dynamic linker resolves libc's, libstdc++'s, FFTW's,
// TBB's... calls to them too) and forwards to glibc's allocator (__libc_malloc & co).
// Calls made on a thread marked as the audio thread are counted; all others pass straight
// through, so Catch2, TBB and the other threads are unaffected.
//
// Usage (a test's audio-role thread):
//   std::thread audio([&] {
//     dpc::rt::AllocationScope scope;   // marks this thread, counts from here
//     for (...) renderBlock();
//     heapCalls = scope.counts().total();
//   });
// or markAudioThread(true) / audioThreadAllocations() / markAudioThread(false).
//
// Link tests/rt/alloc_counter.cpp into the test executable (tests/CMakeLists.txt does this
// for tests/rt/*_test.cpp). Not usable with ThreadSanitizer/AddressSanitizer builds, which
// replace the allocator themselves (tests/rt/*_tsan_test.cpp are built without it).
#pragma once

#include <memory>

#include <cstdint>

namespace dpc::rt {

/// Heap calls counted on marked threads, by kind. new/delete are counted separately from
/// malloc/free (operator new does not also count as a malloc).
struct AllocationCounts {
  uint64_t malloc = 0, calloc = 0, realloc = 0, free = 0;
  uint64_t aligned = 0;  ///< aligned_alloc, posix_memalign, memalign, valloc, pvalloc
  uint64_t newCalls = 0, deleteCalls = 0;
  /// Every heap call (free(nullptr) and delete of nullptr count too: they are still calls
  /// into the allocator).
  uint64_t total() const {
    return malloc + calloc + realloc + free + aligned + newCalls + deleteCalls;
  }
  AllocationCounts operator-(const AllocationCounts& o) const;
};

/// Marks (true) or unmarks the calling thread as the audio thread: its heap calls are
/// counted. Any thread; a thread_local store, no allocation.
void markAudioThread(bool isAudio = true) noexcept;
/// Whether the calling thread is marked.
bool isMarkedAudioThread() noexcept;

/// Heap calls made by all marked threads since program start (or the last reset). Any
/// thread; relaxed atomic reads, no allocation. Read after joining the audio thread (or
/// with it stopped) for a consistent figure.
AllocationCounts audioThreadAllocations() noexcept;
/// Zeroes the counters and the first-call address.
void resetAudioThreadAllocations() noexcept;

/// Return address (inside the caller of malloc/new...) of the first counted heap call since
/// the last reset, or nullptr: for `addr2line -f -C -e TEST ADDRESS` (or describeAddress)
/// when a test finds a heap call on the audio thread.
void* firstAudioAllocationCaller() noexcept;
/// "function+offset (object)" or "object+offset" (for addr2line) for an address, via
/// dladdr, written into buffer. Control thread; no allocation of its own.
const char* describeAddress(void* address, char* buffer, int bufferSize) noexcept;

/// RAII: marks the calling thread for its lifetime and remembers the counts at construction,
/// so counts() is what this scope's thread (and any other marked thread) did since. Not
/// movable; construct and destroy on the same thread.
class AllocationScope {
 public:
  AllocationScope() noexcept;
  ~AllocationScope();
  AllocationScope(const AllocationScope&) = delete;
  AllocationScope& operator=(const AllocationScope&) = delete;
  AllocationCounts counts() const noexcept { return audioThreadAllocations() - start_; }

 private:
  AllocationCounts start_;
  bool wasMarked_;
};

/// An audio-thread observer for test::driveLiveSession (tests/rt/live_driver.h): counts the
/// heap calls on the thread between begin() and end().
struct CountHeapCalls {
  std::unique_ptr<AllocationScope> scope;
  uint64_t calls = ~0ull;
  void begin() { scope = std::make_unique<AllocationScope>(); }
  void end() {
    calls = scope->counts().total();
    scope.reset();
  }
};

}  // namespace dpc::rt
