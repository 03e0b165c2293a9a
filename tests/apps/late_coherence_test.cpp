// The late binaural field's interaural coherence per octave follows the diffuse-field
// coherence of the HRTF set, as a user renders it (dpc-demo --output binaural --ir-out on the
// shipped hall, two listener positions, the default KEMAR set; a Neumann KU 100 set,
// tests/data/, over four seeds).
//
// Oracle, computed here from the SOFA file with libmysofa and FFTW, not through dpc: every
// measured HRIR pair weighted by the solid angle it stands for (the share of 20,000 evenly
// spread directions nearest to it; directions below the lowest measured ring take that ring),
// coherence = Re sum H_L H_R* / sqrt(sum |H_L|^2 sum |H_R|^2) over the directions and the
// octave's bins. The rendered coherence is the same quantity of the IR's two ears over its
// late part, 150-800 ms (testing/octave_correlation.h).
//
// Tolerance: within max(0.15, 3 sigma) of the oracle from 500 Hz to 8 kHz and max(0.2,
// 3 sigma) at 250 Hz, sigma the estimate's sampling deviation over the decaying late part
// (testing/octave_correlation.h, scaled by 1 - rho^2 for a coherence rho: Fisher's
// transformation); 0.15 is about the just-noticeable difference of interaural coherence at
// the diffuse-field values from 0 to 0.6 (Gabriel and Colburn, JASA 69, 1981, report 0.1 to
// 0.3 below a reference coherence of 0.6). 63 and 125 Hz are rendered omnidirectionally
// (coherence 1; the oracle reads 0.9 and more there) and are not checked.
#include <mysofa.h>

#include <algorithm>
#include <array>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "audio/wav_io.h"
#include "testing/octave_correlation.h"

namespace fs = std::filesystem;
using dpc::test::Spectrum;

namespace {

const std::string kDemo = std::string(DPC_BINARY_DIR) + "/apps/dpc-demo";
const std::string kSofa = "/usr/share/libmysofa/default.sofa";
const std::array<double, 7> kCentres{125, 250, 500, 1000, 2000, 4000, 8000};

/// The oracle's coherence per band of kCentres (file comment).
std::array<double, 7> diffuseFieldCoherence(const std::string& sofa) {
  int err = 0;
  std::unique_ptr<MYSOFA_HRTF, void (*)(MYSOFA_HRTF*)> h(mysofa_load(sofa.c_str(), &err),
                                                          mysofa_free);
  REQUIRE(h);
  REQUIRE(h->R == 2);
  mysofa_tocartesian(h.get());
  const size_t M = h->M, N = h->N;
  std::vector<double> weight(M, 0.0);
  constexpr int kGrid = 20000;
  for (int i = 0; i < kGrid; ++i) {  // spherical Fibonacci lattice
    const double z = 1.0 - (2.0 * i + 1.0) / kGrid, r = std::sqrt(1.0 - z * z);
    const double phi = i * M_PI * (3.0 - std::sqrt(5.0));
    size_t best = 0;
    double bestDot = -2.0;
    for (size_t m = 0; m < M; ++m) {
      const float* p = h->SourcePosition.values + 3 * m;
      const double norm = std::sqrt(double(p[0]) * p[0] + double(p[1]) * p[1] + double(p[2]) * p[2]);
      const double dot = (r * std::cos(phi) * p[0] + r * std::sin(phi) * p[1] + z * p[2]) / norm;
      if (dot > bestDot) bestDot = dot, best = m;
    }
    weight[best] += 1.0;
  }
  const double rate = h->DataSamplingRate.values[0];
  const size_t n = 8192;
  std::array<double, 7> cross{}, left{}, right{};
  for (size_t m = 0; m < M; ++m) {
    if (weight[m] == 0.0) continue;
    std::vector<float> l(n, 0.f), r(n, 0.f);
    std::copy_n(h->DataIR.values + (2 * m) * N, N, l.begin());
    std::copy_n(h->DataIR.values + (2 * m + 1) * N, N, r.begin());
    const Spectrum L = dpc::test::spectrum(l, 0, n), R = dpc::test::spectrum(r, 0, n);
    for (size_t k = 0; k < L.size(); ++k) {
      const double hz = double(k) * rate / double(n);
      for (size_t b = 0; b < kCentres.size(); ++b) {
        if (hz < kCentres[b] / std::sqrt(2.0) || hz >= kCentres[b] * std::sqrt(2.0)) continue;
        cross[b] += weight[m] * (L[k] * std::conj(R[k])).real();
        left[b] += weight[m] * std::norm(L[k]);
        right[b] += weight[m] * std::norm(R[k]);
      }
    }
  }
  std::array<double, 7> rho{};
  for (size_t b = 0; b < rho.size(); ++b) rho[b] = cross[b] / std::sqrt(left[b] * right[b]);
  return rho;
}

/// The hall (paths made absolute) with a static listener at `position`, binaural, its IRs
/// written by dpc-demo --ir-out and read back.
dpc::audio::AudioData renderHallAt(const std::string& name, const std::array<double, 3>& position) {
  const fs::path dir = fs::path(DPC_BINARY_DIR) / "late_coherence_test" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ifstream in(std::string(DPC_SOURCE_DIR) + "/scenes/hall.json");
  nlohmann::json j = nlohmann::json::parse(in);
  const std::string scenes = std::string(DPC_SOURCE_DIR) + "/scenes/";
  j["mesh"] = scenes + j["mesh"].get<std::string>();
  for (nlohmann::json& s : j["sources"]) s["signal"] = scenes + s["signal"].get<std::string>();
  j["listener"].erase("trajectory");
  j["listener"]["position"] = position;
  std::ofstream(dir / "scene.json") << j.dump(2);
  const std::string cmd = kDemo + " " + (dir / "scene.json").string() + " --offline " +
                          (dir / "out.wav").string() +
                          " --duration 0.5 --quiet --output binaural --ir-out " +
                          (dir / "ir.wav").string() + " > " + (dir / "log.txt").string() + " 2>&1";
  REQUIRE(std::system(cmd.c_str()) == 0);
  return dpc::audio::readWav((dir / "ir.wav").string());
}

/// The hall as above with one source playing a one-sample click, rendered offline by dpc-demo
/// with `flags` for 1 s: its binaural output is the IR the listener hears (the late part
/// from the frames' IRs the convolver swaps to).
dpc::audio::AudioData renderClickAt(const std::string& name, const std::array<double, 3>& position,
                                    const std::string& flags) {
  const fs::path dir = fs::path(DPC_BINARY_DIR) / "late_coherence_test" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  dpc::audio::AudioData click;
  click.sampleRate = 48000;
  click.channels = {std::vector<float>(48000, 0.f)};
  click.channels[0][0] = 1.f;
  dpc::audio::writeWav((dir / "click.wav").string(), click);
  std::ifstream in(std::string(DPC_SOURCE_DIR) + "/scenes/hall.json");
  nlohmann::json j = nlohmann::json::parse(in);
  j["mesh"] = std::string(DPC_SOURCE_DIR) + "/scenes/" + j["mesh"].get<std::string>();
  nlohmann::json source = j["sources"][0];
  source["signal"] = (dir / "click.wav").string();
  source["loop"] = false;
  j["sources"] = nlohmann::json::array({source});
  j["listener"].erase("trajectory");
  j["listener"]["position"] = position;
  std::ofstream(dir / "scene.json") << j.dump(2);
  const std::string cmd = kDemo + " " + (dir / "scene.json").string() + " --offline " +
                          (dir / "out.wav").string() + " --duration 1 --quiet " + flags + " > " +
                          (dir / "log.txt").string() + " 2>&1";
  REQUIRE(std::system(cmd.c_str()) == 0);
  return dpc::audio::readWav((dir / "out.wav").string());
}

/// Each source's ears (channels 2s, 2s + 1) against the oracle, 250 Hz to 8 kHz.
void requireDiffuseCoherence(const dpc::audio::AudioData& ir, const std::array<double, 7>& want) {
  const size_t begin = size_t(0.15 * ir.sampleRate), end = size_t(0.8 * ir.sampleRate);
  for (size_t s = 0; 2 * s + 1 < ir.channels.size(); ++s) {
    const Spectrum l = dpc::test::spectrum(ir.channels[2 * s], begin, end);
    const Spectrum r = dpc::test::spectrum(ir.channels[2 * s + 1], begin, end);
    for (size_t b = 1; b < kCentres.size(); ++b) {
      const dpc::test::Correlation c =
          dpc::test::octaveCorrelation(l, r, int(end - begin), ir.sampleRate, kCentres[b]);
      const double sigma = c.sigma * (1.0 - want[b] * want[b]);
      const double bound = std::max(b == 1 ? 0.2 : 0.15, 3.0 * sigma);
      INFO("source " << s << ", " << kCentres[b] << " Hz: rendered " << c.value << ", HRTF "
                     << want[b] << ", bound " << bound);
      CHECK(std::abs(c.value - want[b]) <= bound);
    }
  }
}

/// Click renders at the balcony with `flags` and --seed 1..kSeeds: the mean of their late
/// coherence per band within max(0.15, 3 sigma / 2) of `want` (0.2 at 250 Hz), sigma each
/// seed's sampling deviation (scaled as in requireDiffuseCoherence), averaged over the seeds.
void requireSeedMeanCoherence(const std::string& name, const std::string& flags,
                              const std::array<double, 7>& want) {
  constexpr int kSeeds = 4;
  std::array<double, 7> mean{}, sigma{};
  for (int seed = 1; seed <= kSeeds; ++seed) {
    const dpc::audio::AudioData ir = renderClickAt(name + "_" + std::to_string(seed),
                                                   {28.5, 1.6, 10.0},
                                                   flags + " --seed " + std::to_string(seed));
    const size_t begin = size_t(0.15 * ir.sampleRate), end = size_t(0.8 * ir.sampleRate);
    const Spectrum l = dpc::test::spectrum(ir.channels[0], begin, end);
    const Spectrum r = dpc::test::spectrum(ir.channels[1], begin, end);
    for (size_t b = 1; b < kCentres.size(); ++b) {
      const dpc::test::Correlation c =
          dpc::test::octaveCorrelation(l, r, int(end - begin), ir.sampleRate, kCentres[b]);
      mean[b] += c.value / kSeeds;
      sigma[b] += c.sigma * (1.0 - want[b] * want[b]) / kSeeds;
    }
  }
  for (size_t b = 1; b < kCentres.size(); ++b) {
    const double bound = std::max(b == 1 ? 0.2 : 0.15, 3.0 * sigma[b] / std::sqrt(double(kSeeds)));
    INFO(kCentres[b] << " Hz: mean " << mean[b] << ", HRTF " << want[b] << ", bound " << bound);
    CHECK(std::abs(mean[b] - want[b]) <= bound);
  }
}

}  // namespace

TEST_CASE("The late binaural field has the HRTF set's diffuse-field coherence",
          "[spatial][heavy]") {
  const std::array<double, 7> want = diffuseFieldCoherence(kSofa);
  // Under the balcony (the hall's start position) and in the stalls' centre aisle.
  requireDiffuseCoherence(renderHallAt("balcony", {28.5, 1.6, 10.0}), want);
  requireDiffuseCoherence(renderHallAt("aisle", {15.0, 1.6, 10.0}), want);
}

TEST_CASE("A second HRTF set (Neumann KU 100): the late field's coherence, mean of 4 seeds, "
          "is the set's",
          "[spatial][heavy]") {
  // One IR's late coherence scatters from seed to seed by more than the estimate's sampling
  // deviation alone (measured on this set at 1 kHz: -0.25, 0.15, 0.08, -0.08 over seeds 1-4),
  // so the expectation is checked: the mean over 4 seeds within max(0.15, 3 sigma / 2) of
  // the set's diffuse field, sigma each seed's sampling deviation.
  const std::string sofa = std::string(DPC_SOURCE_DIR) + "/tests/data/FHK_HRIR_L2354.sofa";
  requireSeedMeanCoherence("ku100", "--output binaural --hrtf " + sofa, diffuseFieldCoherence(sofa));
}

TEST_CASE("Ambisonics decoded binaurally (MagLS), orders 2, 3 and 5: the late field's coherence "
          "is the HRTF set's",
          "[spatial][ambisonics][heavy]") {
  const std::array<double, 7> want = diffuseFieldCoherence(kSofa);
  for (int order : {2, 3, 5}) {
    INFO("order " << order);
    requireDiffuseCoherence(
        renderClickAt("ambix" + std::to_string(order), {28.5, 1.6, 10.0},
                      "--output ambisonic_binaural --ambisonic-order " + std::to_string(order)),
        want);
  }
}

TEST_CASE("Ambisonics decoded binaurally (MagLS), order 1: the late field's coherence, mean of 4 "
          "seeds, is the HRTF set's",
          "[spatial][ambisonics][heavy]") {
  // Order 1's late field comes from 8 directions, and one IR's decoded coherence at 8 kHz
  // scatters from seed to seed (the seed also moves the rays, hence the directions' energies)
  // by more than its sampling deviation: -0.18, 0.01, -0.10, 0.01, -0.14, -0.06, 0.03, -0.13
  // over seeds 1-8 (KEMAR's diffuse field: -0.01), so, as for the KU 100 above, the mean over
  // 4 seeds is checked. Without the decoder's covariance constraint every seed reads about
  // 0.6 / 0.5 at 2 / 4 kHz (MagLS alone leaves a diffuse first-order field that coherent).
  requireSeedMeanCoherence("ambix1", "--output ambisonic_binaural --ambisonic-order 1",
                           diffuseFieldCoherence(kSofa));
}
