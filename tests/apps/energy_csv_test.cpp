// Energy-response export (dpc-demo --er-out): the CSV round-trips, and its analysis agrees with
// the energy response's.
#include <catch2/catch.hpp>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

#include "audio/room_parameters.h"
#include "engine/energy_response_csv.h"
#include "engine/input_error.h"

using namespace dpc;

TEST_CASE("Energy-response CSV round-trips bins and the direct sound", "[er-out]") {
  SourceEnergy a;
  a.energy = EnergyResponse(0.5, 1e-3);
  for (size_t k = 10; k < a.energy.binCount(); ++k)
    for (int b = 0; b < kNumBands; ++b)
      a.energy.bins()[k][b] = float(1e-3 * std::exp(-double(k) / (50.0 + 10.0 * b)));
  a.direct.visible = true;
  a.direct.delaySeconds = 0.00731f;
  a.direct.intensity = Bands(0.01f);
  SourceEnergy occluded = a;
  occluded.direct.visible = false;
  const std::string path = std::string(DPC_BINARY_DIR) + "/energy_csv_test.csv";
  writeEnergyCsv(path, {a, occluded});
  const auto back = readEnergyCsv(path);
  REQUIRE(back.size() == 2);
  CHECK(back[0].direct.visible);
  CHECK_FALSE(back[1].direct.visible);
  CHECK(back[0].direct.delaySeconds == Approx(0.00731f).epsilon(1e-7));
  REQUIRE(back[0].energy.binCount() == a.energy.binCount());
  CHECK(back[0].energy.binSeconds() == Approx(1e-3));
  for (size_t k = 0; k < a.energy.binCount(); ++k)
    for (int b = 0; b < kNumBands; ++b)  // %.9g keeps a float exactly
      REQUIRE(back[0].energy.bins()[k][b] == a.energy.bins()[k][b]);
  // G of a lone direct sound at 10 m is 0 dB by definition.
  SourceEnergy free;
  free.energy = EnergyResponse(0.1, 1e-3);
  free.direct.visible = true;
  free.direct.delaySeconds = 10.f / 343.f;
  free.direct.intensity = Bands(float(1.0 / (4.0 * 3.14159265358979 * 100.0)));
  const auto e = withDirect(free);
  const auto r = audio::analyzeEnergyDecay(e[3].data(), e[3].size(), 1e-3);
  CHECK(audio::strengthDb(r.energy) == Approx(0.0).margin(1e-5));
  std::remove(path.c_str());
}

TEST_CASE("Energy-response CSV: bad input names the file and the line", "[er-out]") {
  const std::string path = std::string(DPC_BINARY_DIR) + "/energy_csv_bad.csv";
  {
    std::ofstream f(path);
    f << "source,kind,time_s,e63,e125,e250,e500,e1000,e2000,e4000,e8000\n0,bin,0,1,2,3\n";
  }
  try {
    readEnergyCsv(path);
    FAIL("no error");
  } catch (const InputError& e) {
    CHECK(std::string(e.what()).find("energy_csv_bad.csv: line 2") != std::string::npos);
  }
  std::remove(path.c_str());
}

TEST_CASE("dpc-demo --er-out writes what dpc-analyze reads, live mode refuses it", "[er-out]") {
  const std::string bin = std::string(DPC_BINARY_DIR) + "/apps/";
  const std::string scene = std::string(DPC_SOURCE_DIR) + "/scenes/shoebox-corner.json";
  const std::string dir = std::string(DPC_BINARY_DIR) + "/er_out_test";
  std::system(("mkdir -p " + dir).c_str());
  const std::string csv = dir + "/er.csv";
  std::remove(csv.c_str());
  const int demo =
      std::system((bin + "dpc-demo " + scene + " --offline " + dir +
                   "/out.wav --duration 0.3 --rays 512 --quiet --er-out " + csv + " >/dev/null")
                      .c_str());
  REQUIRE(demo == 0);
  const auto sources = readEnergyCsv(csv);
  REQUIRE(sources.size() == 1);
  // The listener starts behind the partition: the direct sound is the diffracted one.
  CHECK(sources[0].direct.visible);
  CHECK(sources[0].energy.binSeconds() == Approx(1e-3));
  CHECK(std::system((bin + "dpc-analyze " + csv + " --json >/dev/null").c_str()) == 0);
  // Without --offline: one-line error naming the flag, non-zero exit, no file.
  const std::string live = dir + "/live.csv";
  const int refused =
      std::system((bin + "dpc-demo " + scene + " --er-out " + live + " 2>/dev/null").c_str());
  CHECK(refused != 0);
  CHECK_FALSE(std::ifstream(live).good());
  std::system(("rm -rf " + dir).c_str());
}
