// dpc-analyze --json on a file whose name is not UTF-8 (Linux file names are bytes): valid JSON
// with U+FFFD for the bad bytes, exit 0, instead of the JSON library's exception.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "audio/wav_io.h"

TEST_CASE("dpc-analyze --json survives a non-UTF-8 file name", "[analyze]") {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(DPC_BINARY_DIR) / "analyze_names_test";
  fs::remove_all(dir);
  fs::create_directories(dir);
  // A decaying noise-free impulse response: exponential decay of a 1 kHz tone, 0.5 s.
  dpc::audio::AudioData ir;
  ir.sampleRate = 48000;
  ir.channels.assign(1, std::vector<float>(24000));
  for (size_t n = 0; n < ir.channels[0].size(); ++n)
    ir.channels[0][n] = float(std::exp(-double(n) / 4800.0) * std::sin(2e3 * M_PI * n / 48000.0));
  const std::string name = (dir / "ir-\xff\xfe-latin1-\xe9.wav").string();
  dpc::audio::writeWav(name, ir);
  const std::string out = (dir / "out.json").string();
  const std::string cmd =
      std::string(DPC_BINARY_DIR) + "/apps/dpc-analyze '" + name + "' --json > " + out + " 2>&1";
  REQUIRE(std::system(cmd.c_str()) == 0);
  std::ifstream f(out);
  std::stringstream text;
  text << f.rdbuf();
  const nlohmann::json j = nlohmann::json::parse(text.str());  // throws if not valid JSON
  const std::string file = j.at("file").get<std::string>();
  CHECK(file.find("\xef\xbf\xbd") != std::string::npos);  // U+FFFD in UTF-8
  CHECK(file.find("latin1") != std::string::npos);
  fs::remove_all(dir);
}

TEST_CASE("dpc-analyze --air-attenuation prints dpc's ISO 9613-1 values, refuses bad values",
          "[analyze]") {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(DPC_BINARY_DIR) / "analyze_air_test";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string out = (dir / "air.json").string();
  const std::string tool = std::string(DPC_BINARY_DIR) + "/apps/dpc-analyze";
  REQUIRE(std::system((tool + " --air-attenuation 20 70 --json > " + out).c_str()) == 0);
  std::ifstream f(out);
  std::stringstream text;
  text << f.rdbuf();
  const nlohmann::json j = nlohmann::json::parse(text.str());
  const auto m = j.at("energyAttenuationPerMetre").get<std::vector<double>>();
  REQUIRE(m.size() == 8);
  // ISO 9613-2:1996 table 2 at 20 C, 70 % RH: 5.0 dB/km at 1 kHz, 76.6 dB/km at 8 kHz. dpc
  // evaluates the exact base-2 centres (1000, 8192 Hz): 3 % at 1 kHz (the table's rounding),
  // 8 % at 8 kHz (alpha grows about as f^2 there: (8192/8000)^2 = 1.049). m = (dB/km) /
  // (1000 * 10 log10 e).
  const double dbPerKm = 1000.0 * 10.0 / std::log(10.0);
  CHECK(m[4] * dbPerKm == Approx(5.0).epsilon(0.03));
  CHECK(m[7] * dbPerKm == Approx(76.6).epsilon(0.08));
  for (size_t b = 1; b < m.size(); ++b) CHECK(m[b] > m[b - 1]);
  // Out of range: exit 1, one line naming the flag.
  const std::string err = (dir / "err.txt").string();
  CHECK(std::system((tool + " --air-attenuation 20 150 2> " + err).c_str()) != 0);
  std::ifstream e(err);
  std::string line;
  std::getline(e, line);
  CHECK(line.find("--air-attenuation") != std::string::npos);
  fs::remove_all(dir);
}
