// dpc-analyze --iacc as a user runs it on dpc-demo's --ir-out of a binaural render: channels
// in (left, right) pairs, one pair per source. The ears of the first pair hear one noise
// (the right 0.5 ms later), those of the second independent noises: IACC 1 and the noise floor
// (about 4 / sqrt(fs T) broadband for T = 1 s, see interaural_correlation_test.cpp). Bad
// input: an odd channel count and an energy response are refused in one line, nothing on
// stdout.
#include <catch2/catch.hpp>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <string>

#include "audio/wav_io.h"

namespace fs = std::filesystem;

namespace {

const std::string kTool = std::string(DPC_BINARY_DIR) + "/apps/dpc-analyze";
constexpr int kRate = 48000;

std::vector<float> noise(uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> g(0.f, 0.1f);
  std::vector<float> x(kRate);
  for (float& v : x) v = g(rng);
  return x;
}

std::string firstLine(const fs::path& path) {
  std::ifstream f(path);
  std::string line;
  std::getline(f, line);
  return line;
}

}  // namespace

TEST_CASE("dpc-analyze --iacc reads each source's pair of ears", "[analyze]") {
  const fs::path dir = fs::path(DPC_BINARY_DIR) / "analyze_iacc_test";
  fs::remove_all(dir);
  fs::create_directories(dir);
  dpc::audio::AudioData ir;
  ir.sampleRate = kRate;
  const std::vector<float> common = noise(1);
  std::vector<float> later(kRate, 0.f);
  for (size_t i = 24; i < later.size(); ++i) later[i] = common[i - 24];
  ir.channels = {common, later, noise(2), noise(3)};
  const fs::path wav = dir / "binaural.wav", out = dir / "iacc.json";
  dpc::audio::writeWav(wav.string(), ir);
  REQUIRE(std::system((kTool + " " + wav.string() + " --iacc --json > " + out.string()).c_str()) ==
          0);
  std::ifstream f(out);
  const nlohmann::json j = nlohmann::json::parse(f);
  REQUIRE(j.at("pairs").size() == 2);
  CHECK(j["pairs"][0]["left"] == 1);
  CHECK(j["pairs"][0]["right"] == 2);
  CHECK(j["pairs"][0]["broadband"]["iaccL"].get<double>() > 0.99);
  CHECK(j["pairs"][0]["mean500to2000"]["iaccE"].get<double>() > 0.98);
  CHECK(j["pairs"][1]["broadband"]["iaccL"].get<double>() < 0.03);
  CHECK(j["pairs"][1]["bands"][0]["centreHz"].get<double>() == Approx(63.0).margin(1.0));

  // Three channels: not pairs of ears. Refused in one line naming the flag.
  ir.channels.pop_back();
  const fs::path odd = dir / "odd.wav", err = dir / "err.txt", none = dir / "none.txt";
  dpc::audio::writeWav(odd.string(), ir);
  CHECK(std::system((kTool + " " + odd.string() + " --iacc > " + none.string() + " 2> " +
                     err.string())
                        .c_str()) != 0);
  CHECK(firstLine(err).find("--iacc") != std::string::npos);
  CHECK(firstLine(err).find(odd.string()) != std::string::npos);
  CHECK(fs::file_size(none) == 0);
  // With --channel: refused by the parser.
  CHECK(std::system((kTool + " " + wav.string() + " --iacc --channel 1 > " + none.string() +
                     " 2> " + err.string())
                        .c_str()) != 0);
  CHECK(firstLine(err).find("--iacc") != std::string::npos);
  fs::remove_all(dir);
}
