// FFTW's planner is not thread-safe; dpc makes and destroys every plan under one lock
// (common/fftw_util.h), so that two engines can be built, stepped and destroyed on two
// threads at once (a game with two engines, the Python module's threads). Without the lock
// this test's threads corrupt the planner: "FFTW plan failed", an abort or a hang within a
// few hundred plans on a 2-core machine.
#include <catch2/catch.hpp>
#include <cmath>
#include <thread>
#include <vector>

#include "audio/convolver.h"
#include "common/fftw_util.h"

namespace {

/// Plans, uses and destroys transforms of varying sizes; returns how many gave a wrong
/// spectrum for a unit impulse (every bin 1 + 0i). Tolerance 1e-4: float rounding over the
/// transform's stages, sizes with a large prime factor (32 x 97) included, stays below 1e-6 (at
/// most 4.8e-7 over these sizes); a corrupted plan is wrong by O(1).
int planAndUse(int seed, int iterations) {
  int wrong = 0;
  for (int i = 0; i < iterations; ++i) {
    const size_t n = size_t(32 * (1 + (i * 7 + seed * 13) % 97));
    dpc::FftwRealTransforms t(n);
    std::fill(t.time.p, t.time.p + n, 0.0f);
    t.time.p[0] = 1.0f;
    fftwf_execute(t.fwd);
    for (size_t k = 0; k <= n / 2; ++k)
      if (std::abs(t.spec.p[k][0] - 1.0f) > 1e-4f || std::abs(t.spec.p[k][1]) > 1e-4f) {
        ++wrong;
        break;
      }
    // The convolvers' split-spectrum plans share the planner.
    dpc::audio::ConvolverLayout layout(16 * (1 + (i + seed) % 17), 4096);
  }
  return wrong;
}

}  // namespace

TEST_CASE("FFTW plans made and destroyed on one thread are correct", "[fftw]") {
  CHECK(planAndUse(3, 200) == 0);
}

TEST_CASE("FFTW plans made and destroyed on two threads at once are correct", "[fftw]") {
  constexpr int kIterations = 600;
  int wrong[2] = {-1, -1};
  std::thread a([&] { wrong[0] = planAndUse(1, kIterations); });
  std::thread b([&] { wrong[1] = planAndUse(2, kIterations); });
  a.join();
  b.join();
  CHECK(wrong[0] == 0);
  CHECK(wrong[1] == 0);
}
