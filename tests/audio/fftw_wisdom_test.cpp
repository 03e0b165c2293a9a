// Measured FFT plans are kept as FFTW wisdom between runs (common/fftw_wisdom.h): a measured
// ConvolverLayout writes the wisdom file, and that file alone lets FFTW make the same plans
// without measuring (FFTW_WISDOM_ONLY returns a plan only when wisdom covers it). A file that
// cannot be written costs nothing but the saving.
#include <fftw3.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <vector>

#include "audio/convolver.h"
#include "common/fftw_util.h"
#include "common/fftw_wisdom.h"
#include "testing/temp_dir.h"

using namespace dpc;
namespace fs = std::filesystem;

namespace {

/// Whether FFTW can make the layout's forward transform (2 x block points, split format with
/// the imaginary parts a multiple of 16 floats after the real ones, as audio/convolver.cpp
/// plans it) from wisdom alone.
bool planFromWisdomOnly(int block) {
  const int n = 2 * block;
  const size_t stride = (size_t(block) + 1 + 15) / 16 * 16;
  float* time = fftwf_alloc_real(size_t(n));
  float* spec = fftwf_alloc_real(2 * stride);
  fftwf_iodim dim{n, 1, 1};
  std::lock_guard lock(fftwPlannerMutex());
  fftwf_plan p = fftwf_plan_guru_split_dft_r2c(1, &dim, 0, nullptr, time, spec, spec + stride,
                                               FFTW_MEASURE | FFTW_WISDOM_ONLY);
  const bool made = p != nullptr;
  if (p) fftwf_destroy_plan(p);
  fftwf_free(time);
  fftwf_free(spec);
  return made;
}

}  // namespace

TEST_CASE("Measured plans are written as FFTW wisdom and made from it alone", "[fftw]") {
  const test::TempDir dir("fftw_wisdom_test");
  const fs::path file = dir.path() / "cache" / "wisdom";
  REQUIRE(setenv("DPC_FFTW_WISDOM", file.c_str(), 1) == 0);
  CHECK(fftwWisdomPath() == file.string());
  { audio::ConvolverLayout layout(96, 4096, audio::ConvolverLayout::Planning::kMeasure); }
  REQUIRE(fs::exists(file));
  CHECK(fs::file_size(file) > 0);
  {
    std::lock_guard lock(fftwPlannerMutex());
    fftwf_forget_wisdom();
  }
  CHECK_FALSE(planFromWisdomOnly(96));  // forgotten: FFTW would have to measure
  {
    std::lock_guard lock(fftwPlannerMutex());
    REQUIRE(fftwf_import_wisdom_from_filename(file.c_str()) != 0);
  }
  CHECK(planFromWisdomOnly(96));
  unsetenv("DPC_FFTW_WISDOM");
}

TEST_CASE("A wisdom file that cannot be written does not stop a measured layout", "[fftw]") {
  REQUIRE(setenv("DPC_FFTW_WISDOM", "/proc/dpc-no-such-folder/wisdom", 1) == 0);
  CHECK_NOTHROW(audio::ConvolverLayout(80, 2048, audio::ConvolverLayout::Planning::kMeasure));
  {
    std::lock_guard lock(fftwPlannerMutex());
    CHECK_FALSE(exportFftwWisdom());
  }
  REQUIRE(setenv("DPC_FFTW_WISDOM", "", 1) == 0);
  CHECK(fftwWisdomPath().empty());
  unsetenv("DPC_FFTW_WISDOM");
}

namespace {

/// Largest |inverse(forward(x)) / 2B - x| over a random block x, through the layout's plans.
double roundTripError(const audio::ConvolverLayout& layout) {
  const size_t n = size_t(layout.fftSize());
  const audio::detail::FftwBuffer time = audio::detail::allocZeroed(n);
  const audio::detail::FftwBuffer spec = audio::detail::allocZeroed(layout.spectrumFloats());
  std::vector<float> x(n);
  for (size_t i = 0; i < n; ++i) x[i] = float((i * 7919) % 211) / 105.f - 1.f;
  std::copy(x.begin(), x.end(), time.get());
  layout.forward(time.get(), spec.get());
  layout.inverse(spec.get(), time.get());
  double err = 0.0;
  for (size_t i = 0; i < n; ++i) err = std::max(err, std::abs(double(time[i]) / double(n) - x[i]));
  return err;
}

}  // namespace

// A live session's convolvers need not wait for FFTW's planner: without wisdom for its sizes a
// kMeasureLater layout starts with estimated plans, and measurePlans() swaps in measured ones
// (and keeps them as wisdom). Oracle: the transforms' round trip, which any correct plan
// passes within float rounding (n log n operations of relative error 6e-8 each: 1e-5 here).
TEST_CASE("A layout measured later starts estimated and swaps in measured plans", "[fftw]") {
  const test::TempDir dir("fftw_wisdom_test_later");
  const fs::path file = dir.path() / "wisdom";
  REQUIRE(setenv("DPC_FFTW_WISDOM", file.c_str(), 1) == 0);
  {
    std::lock_guard lock(fftwPlannerMutex());
    importFftwWisdomOnce();
    fftwf_forget_wisdom();  // nothing this process measured before
  }
  audio::ConvolverLayout layout(112, 4096, audio::ConvolverLayout::Planning::kMeasureLater);
  CHECK_FALSE(layout.plansMeasured());
  CHECK(roundTripError(layout) < 1e-5);
  layout.measurePlans();
  CHECK(layout.plansMeasured());
  CHECK(roundTripError(layout) < 1e-5);
  CHECK(planFromWisdomOnly(112));
  CHECK(fs::exists(file));
  // A second layout of the size finds the wisdom: measured at once.
  audio::ConvolverLayout again(112, 2048, audio::ConvolverLayout::Planning::kMeasureLater);
  CHECK(again.plansMeasured());
  unsetenv("DPC_FFTW_WISDOM");
}
