// dpc studio's IR documents (apps/studio/studio_ir.h) and the board's IR ring: the WAV holds
// the IR's samples bit for bit (read back by libsndfile, the reader dpc-analyze uses); the
// drawn columns are the samples' extremes; IACC is 1 for ears equal up to a delay within 1 ms
// and small for independent ones (ISO 3382-1 Annex B's definition), null when not binaural.
#include "apps/studio/studio_ir.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>

#include "audio/wav_io.h"
#include "testing/temp_dir.h"

using namespace dpc;
using namespace dpc::studio;
using nlohmann::json;

namespace {

/// Two ears of white noise decaying by 60 dB per second; the right ear is the left delayed by
/// `delay` samples, or independent noise when `independent`.
StudioIr noiseIr(size_t delay, bool independent) {
  StudioIr r;
  r.frame = 42;
  r.binaural = true;
  r.ir.resize(2, 48000, 48000.0);
  std::mt19937 rng(3);
  std::normal_distribution<float> n(0.f, 1.f);
  for (int c = 0; c < 2; ++c)
    for (size_t k = 0; k < r.ir.samples(); ++k)
      r.ir.channel(c)[k] = std::pow(10.f, -3.f * float(k) / 48000.f) * n(rng);
  if (!independent)
    for (size_t k = 0; k < r.ir.samples(); ++k)
      r.ir.channel(1)[k] = k >= delay ? r.ir.channel(0)[k - delay] : 0.f;
  return r;
}

}  // namespace

TEST_CASE("studio IR WAV: the IR's samples, bit for bit, as libsndfile reads them") {
  const StudioIr r = noiseIr(7, false);
  test::TempDir dir("dpc_studio_ir");
  const auto file = dir.path() / "ir.wav";
  std::ofstream(file, std::ios::binary) << irWav(r);
  const audio::AudioData a = audio::readWav(file.string());
  REQUIRE(a.sampleRate == 48000);
  REQUIRE(a.channels.size() == 2);
  for (int c = 0; c < 2; ++c) REQUIRE(a.channels[size_t(c)] == r.ir.channelCopy(c));
}

TEST_CASE("studio IR document: column extremes and the envelope of the samples") {
  const StudioIr r = noiseIr(0, true);
  const json d = json::parse(irJson(r));
  REQUIRE(d["frame"] == 42);
  REQUIRE(d["columnSamples"] == 60);  // 48000 samples in kIrColumns = 800 columns
  REQUIRE(d["min"][1].size() == kIrColumns);
  for (size_t k : {size_t(0), size_t(399), size_t(799)}) {
    const float* x = r.ir.channel(1) + 60 * k;
    REQUIRE(d["min"][1][k].get<float>() == *std::min_element(x, x + 60));
    REQUIRE(d["max"][1][k].get<float>() == *std::max_element(x, x + 60));
  }
  // 60 dB per second: the envelope's last 1 ms bin about 60 dB below its first (noise: +-3 dB).
  const json& env = d["envelopeDb"][0];
  REQUIRE(env.size() == 1000);
  REQUIRE(env[999].get<double>() - env[0].get<double>() == Approx(-60.0).margin(3.0));
}

TEST_CASE("studio IR document: IACC 1 for ears equal up to a delay, small for independent") {
  const json same = json::parse(irJson(noiseIr(24, false)))["iacc"];  // 0.5 ms
  REQUIRE(same["broadband"]["early"].get<double>() == Approx(1.0).margin(0.01));
  REQUIRE(same["broadband"]["late"].get<double>() == Approx(1.0).margin(0.01));
  for (int b = 0; b < kNumBands; ++b) REQUIRE(same["bands"][b]["all"].get<double>() > 0.95);
  // Independent noise over 1 s: the correlation's standard deviation ~ 1/sqrt(effective
  // samples), a few hundredths after the max over 97 lags.
  const json indep = json::parse(irJson(noiseIr(0, true)))["iacc"];
  REQUIRE(indep["broadband"]["all"].get<double>() < 0.1);
  StudioIr mono = noiseIr(0, false);
  mono.binaural = false;
  REQUIRE(json::parse(irJson(mono))["iacc"].is_null());
}

TEST_CASE("studio board keeps the newest kKeptIrs IRs and passes on the wish for one") {
  StudioBoard board;
  REQUIRE(board.latestIr() == nullptr);
  for (uint64_t f = 1; f <= StudioBoard::kKeptIrs + 3; ++f) {
    auto r = std::make_shared<StudioIr>();
    r->frame = f;
    board.publishIr(r);
  }
  REQUIRE(board.latestIr()->frame == StudioBoard::kKeptIrs + 3);
  REQUIRE(board.findIr(3) == nullptr);
  REQUIRE(board.findIr(4)->frame == 4);
  // A request for the newest IR asks the control loop for the next frame's, once.
  REQUIRE_FALSE(board.takeIrWanted());
  board.wantIr();
  REQUIRE(board.takeIrWanted());
  REQUIRE_FALSE(board.takeIrWanted());
}
