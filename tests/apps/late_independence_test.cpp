// Two sources in one room excite its diffuse field independently: their late parts at one
// ear (one channel) are uncorrelated, as a user hears them in a render of the shipped hall
// (dpc-demo --ir-out, every spatial output format). The instrument is the test's own: the
// zero-lag normalised correlation of the two channels in one octave (an ideal band-pass in
// the frequency domain: FFTW (single precision) over the late part, 150-800 ms after the first sample), not
// dpc's filters.
//
// Tolerance: for two independent noises the estimate scatters with a standard deviation of
// about 1 / sqrt(N), N the independent frequency samples the octave holds over the decaying
// late part; the test computes N from the data (the participation ratio of the two
// channels' cross-power over the octave's bins, which counts the bins that carry the sum)
// and allows max(0.15, 4 / sqrt(N)): 0.15 is the perceptual bound (two late fields that
// correlate less are heard as independent; a shared field reads 0.5-1), 4 sigma the sampling
// error where the octave holds too few bins for 0.15 to be 3 sigma.
#include <algorithm>
#include <array>
#include <catch2/catch.hpp>
#include <cmath>
#include <complex>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "audio/wav_io.h"
#include "testing/octave_correlation.h"

namespace fs = std::filesystem;

using dpc::test::Spectrum;

namespace {

const std::string kDemo = std::string(DPC_BINARY_DIR) + "/apps/dpc-demo";
const std::string kHall = std::string(DPC_SOURCE_DIR) + "/scenes/hall.json";

/// The hall with its second source `offset` metres from the first (paths made absolute), as
/// a scene file in dir.
std::string hallWithSecondSourceNear(const fs::path& dir, const std::array<double, 3>& offset) {
  std::ifstream in(kHall);
  nlohmann::json j = nlohmann::json::parse(in);
  const std::string scenes = std::string(DPC_SOURCE_DIR) + "/scenes/";
  j["mesh"] = scenes + j["mesh"].get<std::string>();
  for (nlohmann::json& s : j["sources"]) s["signal"] = scenes + s["signal"].get<std::string>();
  for (int i = 0; i < 3; ++i)
    j["sources"][1]["position"][i] = j["sources"][0]["position"][i].get<double>() + offset[size_t(i)];
  const fs::path path = dir / "scene.json";
  std::ofstream(path) << j.dump(2);
  return path.string();
}

/// The IRs dpc-demo writes for `scene`'s two sources with `flags` (one frame's worth of
/// render, 0.5 s), channels source-major.
dpc::audio::AudioData render(const std::string& name, const std::string& flags,
                             const std::array<double, 3>* secondSourceOffset = nullptr) {
  const fs::path dir = fs::path(DPC_BINARY_DIR) / "late_independence_test" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string scene =
      secondSourceOffset ? hallWithSecondSourceNear(dir, *secondSourceOffset) : kHall;
  const std::string cmd = kDemo + " " + scene + " --offline " + (dir / "out.wav").string() +
                          " --duration 0.5 --quiet " + flags + " --ir-out " +
                          (dir / "ir.wav").string() + " > " + (dir / "log.txt").string() + " 2>&1";
  REQUIRE(std::system(cmd.c_str()) == 0);
  return dpc::audio::readWav((dir / "ir.wav").string());
}

/// Every octave from 500 Hz: channel c of source 0 against channel c of source 1.
void requireIndependent(const dpc::audio::AudioData& ir, int channelsPerSource, int c) {
  REQUIRE(int(ir.channels.size()) == 2 * channelsPerSource);
  const size_t begin = size_t(0.15 * ir.sampleRate), end = size_t(0.8 * ir.sampleRate);
  REQUIRE(ir.channels[0].size() >= end);
  const Spectrum u = dpc::test::spectrum(ir.channels[size_t(c)], begin, end);
  const Spectrum v = dpc::test::spectrum(ir.channels[size_t(channelsPerSource + c)], begin, end);
  for (double fc : {500.0, 1000.0, 2000.0, 4000.0, 8000.0}) {
    const dpc::test::Correlation r = dpc::test::octaveCorrelation(u, v, int(end - begin), ir.sampleRate, fc);
    const double bound = std::max(0.15, 3.0 * r.sigma);
    INFO("channel " << c << ", " << fc << " Hz: correlation " << r.value << ", sigma "
                    << r.sigma << ", bound " << bound);
    CHECK(std::abs(r.value) <= bound);
  }
}

}  // namespace

TEST_CASE("Two sources' late fields are uncorrelated: binaural", "[spatial][heavy]") {
  const dpc::audio::AudioData ir = render("binaural", "--output binaural");
  requireIndependent(ir, 2, 0);
  requireIndependent(ir, 2, 1);
}

TEST_CASE("Two sources' late fields are uncorrelated: stereo and AmbiX", "[spatial][heavy]") {
  const dpc::audio::AudioData stereo = render("stereo", "--output stereo");
  requireIndependent(stereo, 2, 0);
  requireIndependent(stereo, 2, 1);
  const dpc::audio::AudioData ambix = render("ambix", "--output ambisonics --ambisonic-order 3");
  requireIndependent(ambix, 16, 0);  // W
  requireIndependent(ambix, 16, 1);  // Y
  requireIndependent(ambix, 16, 9);  // third order
}

TEST_CASE("Two sources 1 m apart: their late fields are uncorrelated, as the room's are",
          "[spatial]") {
  // Their energy responses are nearly the same, so a shared late noise would correlate close
  // to 1; the room's diffuse field correlates sin(kd) / kd between points d = 1 m apart:
  // 0.02 at 500 Hz and less above (Cook et al., JASA 27, 1955), so independence is physics.
  const std::array<double, 3> offset{0.0, 0.0, 1.0};
  const dpc::audio::AudioData ir = render("near_binaural", "--output binaural", &offset);
  requireIndependent(ir, 2, 0);
  requireIndependent(ir, 2, 1);
}

TEST_CASE("Two sources' late fields are uncorrelated: hybrid rendering, one late bus each",
          "[spatial][heavy]") {
  // Sources in one cluster share its late bus by design (docs/cli.md, hybrid rendering);
  // clusters of 2 degrees put the hall's two sources (8 degrees apart) on separate buses,
  // each with its own late field.
  const dpc::audio::AudioData ir =
      render("hybrid", "--output binaural --rendering hybrid --cluster-angle 2");
  requireIndependent(ir, 2, 0);
  requireIndependent(ir, 2, 1);
}
