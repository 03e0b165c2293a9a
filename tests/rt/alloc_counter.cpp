// Interposing allocator: see alloc_counter.h. Every replacement forwards to glibc's own entry
// points (__libc_malloc, __libc_free, ...), exported by glibc for exactly this purpose, so no
// dlsym(RTLD_NEXT) bootstrapping (dlsym itself may call calloc) is needed. The counters are
// relaxed atomics and the mark is an initial-exec thread_local bool: counting allocates
// nothing and calls nothing.
#include "tests/rt/alloc_counter.h"

#include <dlfcn.h>

#include <atomic>
#include <cerrno>
#include <cstddef>
#include <cstdio>
#include <new>

extern "C" {
void* __libc_malloc(size_t);
void* __libc_calloc(size_t, size_t);
void* __libc_realloc(void*, size_t);
void __libc_free(void*);
void* __libc_memalign(size_t, size_t);
void* __libc_valloc(size_t);
void* __libc_pvalloc(size_t);
}

namespace dpc::rt {
namespace {

__attribute__((tls_model("initial-exec"))) thread_local bool tMarked = false;

struct Counters {
  std::atomic<uint64_t> malloc{0}, calloc{0}, realloc{0}, free{0}, aligned{0}, newCalls{0},
      deleteCalls{0};
  std::atomic<void*> firstCaller{nullptr};
};
Counters gCounters;  // constant-initialised (atomics of zero): ready before any constructor

inline void count(std::atomic<uint64_t>& counter, void* caller) noexcept {
  if (!tMarked) return;
  counter.fetch_add(1, std::memory_order_relaxed);
  void* expected = nullptr;
  gCounters.firstCaller.compare_exchange_strong(expected, caller, std::memory_order_relaxed);
}

}  // namespace

AllocationCounts AllocationCounts::operator-(const AllocationCounts& o) const {
  AllocationCounts d;
  d.malloc = malloc - o.malloc;
  d.calloc = calloc - o.calloc;
  d.realloc = realloc - o.realloc;
  d.free = free - o.free;
  d.aligned = aligned - o.aligned;
  d.newCalls = newCalls - o.newCalls;
  d.deleteCalls = deleteCalls - o.deleteCalls;
  return d;
}

void markAudioThread(bool isAudio) noexcept {
  tMarked = isAudio;
}
bool isMarkedAudioThread() noexcept {
  return tMarked;
}

AllocationCounts audioThreadAllocations() noexcept {
  AllocationCounts c;
  c.malloc = gCounters.malloc.load(std::memory_order_relaxed);
  c.calloc = gCounters.calloc.load(std::memory_order_relaxed);
  c.realloc = gCounters.realloc.load(std::memory_order_relaxed);
  c.free = gCounters.free.load(std::memory_order_relaxed);
  c.aligned = gCounters.aligned.load(std::memory_order_relaxed);
  c.newCalls = gCounters.newCalls.load(std::memory_order_relaxed);
  c.deleteCalls = gCounters.deleteCalls.load(std::memory_order_relaxed);
  return c;
}

void resetAudioThreadAllocations() noexcept {
  for (auto* c : {&gCounters.malloc, &gCounters.calloc, &gCounters.realloc, &gCounters.free,
                  &gCounters.aligned, &gCounters.newCalls, &gCounters.deleteCalls}) {
    c->store(0, std::memory_order_relaxed);
  }
  gCounters.firstCaller.store(nullptr, std::memory_order_relaxed);
}

void* firstAudioAllocationCaller() noexcept {
  return gCounters.firstCaller.load(std::memory_order_relaxed);
}

const char* describeAddress(void* address, char* buffer, int bufferSize) noexcept {
  Dl_info info{};
  if (address && dladdr(address, &info) && info.dli_sname) {
    std::snprintf(buffer, size_t(bufferSize), "%s+0x%zx (%s)", info.dli_sname,
                  size_t(static_cast<char*>(address) - static_cast<char*>(info.dli_saddr)),
                  info.dli_fname ? info.dli_fname : "?");
  } else if (address && info.dli_fname) {
    // No dynamic symbol (e.g. the test executable itself): the offset from the object's load
    // address, which addr2line -f -C -e OBJECT OFFSET resolves for PIE executables.
    std::snprintf(buffer, size_t(bufferSize), "%s+0x%zx", info.dli_fname,
                  size_t(static_cast<char*>(address) - static_cast<char*>(info.dli_fbase)));
  } else {
    std::snprintf(buffer, size_t(bufferSize), "%p", address);
  }
  return buffer;
}

AllocationScope::AllocationScope() noexcept
    : start_(audioThreadAllocations()), wasMarked_(isMarkedAudioThread()) {
  markAudioThread(true);
}
AllocationScope::~AllocationScope() {
  markAudioThread(wasMarked_);
}

}  // namespace dpc::rt

// ---------------------------------------------------------------------------------------
// The replacements. __builtin_return_address(0) is the caller's address (for addr2line).

using dpc::rt::count;
using dpc::rt::gCounters;

#define DPC_CALLER __builtin_return_address(0)

extern "C" {

void* malloc(size_t size) {
  count(gCounters.malloc, DPC_CALLER);
  return __libc_malloc(size);
}
void* calloc(size_t n, size_t size) {
  count(gCounters.calloc, DPC_CALLER);
  return __libc_calloc(n, size);
}
void* realloc(void* p, size_t size) {
  count(gCounters.realloc, DPC_CALLER);
  return __libc_realloc(p, size);
}
void free(void* p) {
  count(gCounters.free, DPC_CALLER);
  __libc_free(p);
}
void* memalign(size_t alignment, size_t size) {
  count(gCounters.aligned, DPC_CALLER);
  return __libc_memalign(alignment, size);
}
void* aligned_alloc(size_t alignment, size_t size) {
  count(gCounters.aligned, DPC_CALLER);
  return __libc_memalign(alignment, size);
}
int posix_memalign(void** out, size_t alignment, size_t size) {
  count(gCounters.aligned, DPC_CALLER);
  if (alignment < sizeof(void*) || (alignment & (alignment - 1)) != 0) return EINVAL;
  void* p = __libc_memalign(alignment, size);
  if (!p && size != 0) return ENOMEM;
  *out = p;
  return 0;
}
void* valloc(size_t size) {
  count(gCounters.aligned, DPC_CALLER);
  return __libc_valloc(size);
}
void* pvalloc(size_t size) {
  count(gCounters.aligned, DPC_CALLER);
  return __libc_pvalloc(size);
}

}  // extern "C"

namespace {

void* newImpl(size_t size, void* caller) {
  count(gCounters.newCalls, caller);
  for (;;) {
    if (void* p = __libc_malloc(size ? size : 1)) return p;
    std::new_handler handler = std::get_new_handler();
    if (!handler) throw std::bad_alloc();
    handler();
  }
}
void* newAlignedImpl(size_t size, std::align_val_t alignment, void* caller) {
  count(gCounters.newCalls, caller);
  for (;;) {
    if (void* p = __libc_memalign(static_cast<size_t>(alignment), size ? size : 1)) return p;
    std::new_handler handler = std::get_new_handler();
    if (!handler) throw std::bad_alloc();
    handler();
  }
}
void deleteImpl(void* p, void* caller) noexcept {
  count(gCounters.deleteCalls, caller);
  __libc_free(p);
}

}  // namespace

void* operator new(size_t size) {
  return newImpl(size, DPC_CALLER);
}
void* operator new[](size_t size) {
  return newImpl(size, DPC_CALLER);
}
void* operator new(size_t size, const std::nothrow_t&) noexcept {
  try {
    return newImpl(size, DPC_CALLER);
  } catch (...) {
    return nullptr;
  }
}
void* operator new[](size_t size, const std::nothrow_t&) noexcept {
  try {
    return newImpl(size, DPC_CALLER);
  } catch (...) {
    return nullptr;
  }
}
void* operator new(size_t size, std::align_val_t a) {
  return newAlignedImpl(size, a, DPC_CALLER);
}
void* operator new[](size_t size, std::align_val_t a) {
  return newAlignedImpl(size, a, DPC_CALLER);
}
void* operator new(size_t size, std::align_val_t a, const std::nothrow_t&) noexcept {
  try {
    return newAlignedImpl(size, a, DPC_CALLER);
  } catch (...) {
    return nullptr;
  }
}
void* operator new[](size_t size, std::align_val_t a, const std::nothrow_t&) noexcept {
  try {
    return newAlignedImpl(size, a, DPC_CALLER);
  } catch (...) {
    return nullptr;
  }
}

void operator delete(void* p) noexcept {
  deleteImpl(p, DPC_CALLER);
}
void operator delete[](void* p) noexcept {
  deleteImpl(p, DPC_CALLER);
}
void operator delete(void* p, size_t) noexcept {
  deleteImpl(p, DPC_CALLER);
}
void operator delete[](void* p, size_t) noexcept {
  deleteImpl(p, DPC_CALLER);
}
void operator delete(void* p, const std::nothrow_t&) noexcept {
  deleteImpl(p, DPC_CALLER);
}
void operator delete[](void* p, const std::nothrow_t&) noexcept {
  deleteImpl(p, DPC_CALLER);
}
void operator delete(void* p, std::align_val_t) noexcept {
  deleteImpl(p, DPC_CALLER);
}
void operator delete[](void* p, std::align_val_t) noexcept {
  deleteImpl(p, DPC_CALLER);
}
void operator delete(void* p, size_t, std::align_val_t) noexcept {
  deleteImpl(p, DPC_CALLER);
}
void operator delete[](void* p, size_t, std::align_val_t) noexcept {
  deleteImpl(p, DPC_CALLER);
}
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept {
  deleteImpl(p, DPC_CALLER);
}
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept {
  deleteImpl(p, DPC_CALLER);
}
