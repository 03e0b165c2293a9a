// dpc-analyze --diffuseness as a user runs it on an AmbiX IR of two sources (channels in
// blocks of (N + 1)^2, as dpc-demo --ir-out writes them): the first block one plane wave
// (every channel a multiple of one noise: 0 by both measures), the second independent noises
// at a diffuse field's SN3D powers (1 within the sampling error; the bounds are derived in
// tests/analysis/ambisonic_diffuseness_test.cpp). Bad input: a channel count that is not a
// multiple of the block, an energy response, an order outside 1..7: one line on stderr,
// nothing on stdout, exit status 1.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <string>

#include "audio/wav_io.h"
#include "testing/temp_dir.h"

namespace fs = std::filesystem;

namespace {

const std::string kTool = std::string(DPC_BINARY_DIR) + "/apps/dpc-analyze";
constexpr int kRate = 48000;

std::string contents(const fs::path& p) {
  std::ifstream f(p);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

/// Runs dpc-analyze with args; its exit status, stdout in out, stderr in err.
int run(const std::string& args, const fs::path& out, const fs::path& err) {
  const int status =
      std::system((kTool + " " + args + " > " + out.string() + " 2> " + err.string()).c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace

TEST_CASE("dpc-analyze --diffuseness reads each source's block of AmbiX channels", "[analyze]") {
  const dpc::test::TempDir scratch("analyze_diffuseness_test");
  const fs::path dir = scratch.path();
  dpc::audio::AudioData ir;
  ir.sampleRate = kRate;
  ir.channels.assign(8, std::vector<float>(kRate, 0.f));
  std::mt19937 rng(3);
  std::normal_distribution<float> g(0.f, 0.1f);
  const float plane[4] = {1.f, 0.f, 0.8f, 0.6f};  // W, Y, Z, X of a direction up and ahead
  for (size_t t = kRate / 10; t < size_t(kRate); ++t) {
    const float s = g(rng);
    for (int c = 0; c < 4; ++c) ir.channels[size_t(c)][t] = plane[c] * s;
    ir.channels[4][t] = g(rng);
    for (int c = 5; c < 8; ++c) ir.channels[size_t(c)][t] = g(rng) / std::sqrt(3.f);
  }
  const fs::path wav = dir / "ambix.wav", out = dir / "out.json", err = dir / "err.txt";
  dpc::audio::writeWav(wav.string(), ir);
  REQUIRE(run(wav.string() + " --diffuseness 1 --json", out, err) == 0);
  const nlohmann::json j = nlohmann::json::parse(contents(out));
  REQUIRE(j.at("sources").size() == 2);
  CHECK(j["sources"][0]["firstChannel"] == 1);
  CHECK(j["sources"][1]["firstChannel"] == 5);
  CHECK(j["sources"][0]["broadband"]["dirac"].get<double>() < 0.01);
  CHECK(j["sources"][0]["broadband"]["comedie"].get<double>() < 0.01);
  CHECK(j["sources"][1]["broadband"]["dirac"].get<double>() > 0.95);
  CHECK(j["sources"][1]["broadband"]["comedie"].get<double>() > 0.95);
  // The table names both measures.
  REQUIRE(run(wav.string() + " --diffuseness 1", out, err) == 0);
  CHECK(contents(out).find("COMEDIE") != std::string::npos);

  ir.channels.resize(6);
  const fs::path six = dir / "six.wav";
  dpc::audio::writeWav(six.string(), ir);
  for (const std::string& args : {six.string() + " --diffuseness 1",
                                  wav.string() + " --diffuseness 8",
                                  (dir / "er.csv").string() + " --diffuseness 1"}) {
    if (args.find("er.csv") != std::string::npos) std::ofstream(dir / "er.csv") << "x\n";
    INFO(args);
    CHECK(run(args, out, err) == 1);
    CHECK(contents(out).empty());
    const std::string e = contents(err);
    CHECK(std::count(e.begin(), e.end(), '\n') == 1);
    CHECK(e.find("diffuseness") != std::string::npos);
  }
}
