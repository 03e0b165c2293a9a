// dpc-analyze as a command: --json on a file whose name is not UTF-8 (Linux file names are
// bytes) gives valid JSON with U+FFFD for the bad bytes; --air-attenuation prints ISO 9613-1
// values; --as-measured gives what the band analysis of an exact IR of a response reads.
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
#include "engine/bands.h"
#include "engine/energy_response_csv.h"

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

TEST_CASE("dpc-analyze --as-measured: what the band analysis of an exact IR reads", "[analyze]") {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(DPC_BINARY_DIR) / "analyze_as_measured_test";
  fs::remove_all(dir);
  fs::create_directories(dir);
  // A white spectrum (band energy proportional to the octave's width fc / sqrt 2) decaying with
  // T60 = 1 s in every band from 5 ms, and a white direct sound at 3 ms.
  dpc::SourceEnergy s{dpc::EnergyResponse(2.0, 1e-3), dpc::DirectSound{}};
  s.direct.visible = true;
  s.direct.delaySeconds = 0.003f;
  for (int b = 0; b < dpc::kNumBands; ++b) {
    const double width = dpc::bandCentreExactHz(b) / std::sqrt(2.0) / 1000.0;
    s.direct.intensity[b] = float(1e-3 * width);
    for (size_t j = 5; j < s.energy.binCount(); ++j)
      s.energy.bins()[j][b] = float(1e-4 * width * std::pow(10.0, -6.0 * (double(j) + 0.5) * 1e-3));
  }
  const std::string csv = (dir / "white.csv").string();
  dpc::writeEnergyCsv(csv, {s});
  const std::string tool = std::string(DPC_BINARY_DIR) + "/apps/dpc-analyze ";
  auto bands = [&](const std::string& flags) {
    const std::string out = (dir / "out.json").string();
    REQUIRE(std::system((tool + csv + " --json " + flags + " > " + out).c_str()) == 0);
    std::ifstream f(out);
    std::stringstream text;
    text << f.rdbuf();
    return nlohmann::json::parse(text.str()).at("sources").at(0).at("bands");
  };
  const nlohmann::json plain = bands(""), measured = bands("--as-measured");
  std::vector<double> c80Shift;
  for (size_t b = 0; b < 8; ++b) {
    INFO("band " << dpc::kBandCentreHz[b] << " Hz");
    const double dG = measured[b].at("g").get<double>() - plain[b].at("g").get<double>();
    // White noise through a Butterworth band-pass made from an order-3 low-pass prototype
    // carries (pi/6) / sin(pi/6) = pi/3 of the band's energy between its -3 dB edges: G reads
    // 10 log10(pi/3) = 0.20 dB high (125 Hz-2 kHz within 0.015 dB: the model's kernels are
    // truncated and its masks float; at 63 Hz within 0.03 dB, measured 0.176: its half-octave
    // split at 56-71 Hz spreads the first arrivals' energy tens of ms either way, and what
    // falls before the onset is not counted; at 4 and 8 kHz the bilinear transform's
    // frequency warping narrows the digital band: measured 0.18 and 0.12 dB).
    if (b <= 5)
      CHECK(std::abs(dG - 10 * std::log10(M_PI / 3)) < (b == 0 ? 0.03 : 0.015));
    else
      CHECK((dG > 0.05 && dG < 0.2));
    // A filter delays an exponential decay without changing its slope.
    CHECK(measured[b].at("t30").get<double>() ==
          Approx(plain[b].at("t30").get<double>()).epsilon(1e-3));
    c80Shift.push_back(measured[b].at("c80").get<double>() - plain[b].at("c80").get<double>());
    CHECK(c80Shift.back() < 0.0);  // the filter's delay moves early energy past 80 ms
  }
  // The delay of constant-Q filters, hence (to first order) the energy moved past 80 ms,
  // halves per octave: measured ratios 2.06 ... 1.98 from 63 Hz to 4 kHz.
  for (size_t b = 0; b + 1 < 7; ++b) {
    INFO("octaves " << dpc::kBandCentreHz[b] << " and " << dpc::kBandCentreHz[b + 1] << " Hz");
    CHECK((c80Shift[b] / c80Shift[b + 1] > 1.8 && c80Shift[b] / c80Shift[b + 1] < 2.3));
  }
  // An impulse response is already measured: exit 1, one line naming the flag, no output.
  dpc::audio::AudioData ir;
  ir.sampleRate = 48000;
  ir.channels.assign(1, std::vector<float>(4800, 0.f));
  ir.channels[0][10] = 1.f;
  const std::string wav = (dir / "ir.wav").string(), err = (dir / "err.txt").string();
  dpc::audio::writeWav(wav, ir);
  CHECK(std::system(
            (tool + wav + " --as-measured > " + (dir / "o.txt").string() + " 2> " + err).c_str()) !=
        0);
  std::ifstream e(err);
  std::string line;
  std::getline(e, line);
  CHECK(line.find("--as-measured") != std::string::npos);
  CHECK(fs::file_size(dir / "o.txt") == 0);
  fs::remove_all(dir);
}
