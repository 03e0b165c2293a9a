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
