// Measured FFT plans are kept as FFTW wisdom between runs (common/fftw_wisdom.h): a measured
// ConvolverLayout writes the wisdom file, and that file alone lets FFTW make the same plans
// without measuring (FFTW_WISDOM_ONLY returns a plan only when wisdom covers it). A file that
// cannot be written costs nothing but the saving.
#include <fftw3.h>

#include <catch2/catch.hpp>
#include <cstdlib>
#include <filesystem>
#include <mutex>

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
