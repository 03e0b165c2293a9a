// FFTW single-precision buffer ownership, planning and FFT sizing, shared by the IR
// synthesisers and the convolvers. Any thread; FftwArray allocates (throws std::bad_alloc on
// failure); nextPow2 does not. FFTW's planner (creating and destroying plans) is not
// thread-safe: every plan in dpc is made and destroyed under fftwPlannerMutex(), so that two
// engines may be built, stepped and destroyed on two threads at once. Executing a plan is
// thread-safe.
#pragma once

#include <fftw3.h>

#include <algorithm>
#include <cstddef>
#include <mutex>
#include <new>
#include <stdexcept>

namespace dpc {

/// The one lock around FFTW's planner: hold it to create or destroy any plan. Any thread; may
/// block (never on the audio thread, which neither plans nor destroys plans).
inline std::mutex& fftwPlannerMutex() {
  static std::mutex m;
  return m;
}

/// fftwf_malloc of n elements (SIMD-aligned, uninitialised); free with fftwf_free.
template <typename T>
T* fftwAllocate(size_t n) {
  T* p = static_cast<T*>(fftwf_malloc(n * sizeof(T)));
  if (!p) throw std::bad_alloc();
  return p;
}

/// RAII owner of an fftwAllocate'd array of n elements.
template <typename T>
struct FftwArray {
  explicit FftwArray(size_t n) : p(fftwAllocate<T>(n)) {}
  ~FftwArray() { fftwf_free(p); }
  FftwArray(const FftwArray&) = delete;
  FftwArray& operator=(const FftwArray&) = delete;
  T* p;
};

/// An n-point real FFT pair with its buffers: fwd maps time -> spec, inv maps band -> time
/// (FFTW_ESTIMATE; fftwf_execute_dft_r2c/c2r may run them on other fftwAllocate'd arrays of
/// the same sizes). Throws std::bad_alloc, or std::runtime_error when planning fails.
struct FftwRealTransforms {
  explicit FftwRealTransforms(size_t size)
      : n(size), time(size), spec(size / 2 + 1), band(size / 2 + 1) {
    std::lock_guard<std::mutex> lock(fftwPlannerMutex());
    fwd = fftwf_plan_dft_r2c_1d(int(n), time.p, spec.p, FFTW_ESTIMATE);
    inv = fftwf_plan_dft_c2r_1d(int(n), band.p, time.p, FFTW_ESTIMATE);
    if (!fwd || !inv) {
      destroyLocked();
      throw std::runtime_error("FFTW plan failed");
    }
  }
  ~FftwRealTransforms() {
    std::lock_guard<std::mutex> lock(fftwPlannerMutex());
    destroyLocked();
  }
  FftwRealTransforms(const FftwRealTransforms&) = delete;
  FftwRealTransforms& operator=(const FftwRealTransforms&) = delete;
  size_t n;
  FftwArray<float> time;
  FftwArray<fftwf_complex> spec, band;
  fftwf_plan fwd = nullptr, inv = nullptr;

 private:
  void destroyLocked() {
    if (fwd) fftwf_destroy_plan(fwd);
    if (inv) fftwf_destroy_plan(inv);
    fwd = inv = nullptr;
  }
};

/// The smallest multiple of 32 >= n whose only prime factors are 2, 3 and 5: FFTW (with
/// estimated plans) transforms such sizes about as fast per point as powers of two, and they
/// waste less padding (160000 for a 3 s IR at 48 kHz plus 1/4 s of filter reach, where the next
/// power of two is 262144). The factor 32 keeps FFTW off odd-heavy sizes: 156250 = 2 x 5^7 takes
/// 1.6 times as long as 160000 = 2^8 x 5^4.
inline size_t smoothFftSize(size_t n) {
  for (size_t m = std::max<size_t>(32, (n + 31) / 32 * 32);; m += 32) {
    size_t r = m;
    for (size_t p : {2, 3, 5})
      while (r % p == 0) r /= p;
    if (r == 1) return m;
  }
}

/// The smallest power of two >= n (1 for n = 0).
inline size_t nextPow2(size_t n) {
  size_t p = 1;
  while (p < n) p <<= 1;
  return p;
}

}  // namespace dpc
