// Energy-response export (dpc-demo --er-out): the CSV round-trips, and its analysis agrees with
// the energy response's.
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <sys/stat.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "analysis/room_parameters.h"
#include "analysis/energy_response_csv.h"
#include "common/input_error.h"

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

namespace {

/// The InputError text readEnergyCsv throws for a file holding `text` ("" if it reads it).
std::string csvError(const std::string& text) {
  const std::string path = std::string(DPC_BINARY_DIR) + "/energy_csv_damaged.csv";
  std::ofstream(path) << text;
  std::string error;
  try {
    readEnergyCsv(path);
  } catch (const InputError& e) {
    error = e.what();
  }
  std::remove(path.c_str());
  return error;
}

const std::string kHeader = "source,kind,time_s,e63,e125,e250,e500,e1000,e2000,e4000,e8000\n";
const std::string kBins = "0,bin,0.000000,1,1,1,1,1,1,1,1\n0,bin,0.001000,1,1,1,1,1,1,1,1\n";

}  // namespace

TEST_CASE("Energy-response CSV: damaged rows are refused, naming the line", "[er-out]") {
  const std::string direct = "0,direct,0.01,1,1,1,1,1,1,1,1\n";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {kHeader, "no data rows after the header"},
      {kHeader + "0,bin,0.000000,-1,1,1,1,1,1,1,1\n", "line 2: band values must be energies >= 0"},
      {kHeader + "0,bin,0.000000,1e300,1,1,1,1,1,1,1\n", "line 2: band values must be energies"},
      {kHeader + "0,bin,-0.001,1,1,1,1,1,1,1,1\n", "line 2: time_s must be >= 0"},
      {kHeader + "0,bin,0.001000,1,1,1,1,1,1,1,1\n", "line 2: the first bin of a source must start"},
      {kHeader + kBins + "0,bin,0.001000,1,1,1,1,1,1,1,1\n", "line 4: time_s must follow"},
      {kHeader + kBins + "0,bin,0.004000,1,1,1,1,1,1,1,1\n", "line 4: time_s must follow"},
      {kHeader + "0,bin,0,1,1,1,1,1,1,1,1\n0,bin,100,1,1,1,1,1,1,1,1\n", "line 3: time_s must follow"},
      {kHeader + direct + direct + kBins, "line 3: a second direct row for this source"},
      {kHeader + "0,direct,1e300,1,1,1,1,1,1,1,1\n" + kBins, "line 2: time_s must be >= 0"},
  };
  for (const auto& [text, expected] : cases) {
    INFO(text);
    CHECK(csvError(text).find(expected) != std::string::npos);
  }
  // Read as written: CRLF line ends, a direct sound after the last bin (in the last bin).
  std::string crlf;
  for (const char c : kHeader + kBins) crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
  CHECK(csvError(crlf).empty());
  CHECK(csvError(kHeader + "0,direct,3e38,1,1,1,1,1,1,1,1\n" + kBins).empty());
}

TEST_CASE("Energy-response CSV: a table cut short at a line boundary is refused", "[er-out]") {
  // What dpc writes, cut after each of its lines: only the whole file reads. Without the end
  // line a cut at a line boundary is a shorter response that analyses as valid (its T30 from
  // a truncated decay).
  SourceEnergy a;
  a.energy = EnergyResponse(0.004, 1e-3);
  a.energy.bins()[1] = Bands(1.f);
  a.direct.visible = true;
  a.direct.delaySeconds = 0.001f;
  a.direct.intensity = Bands(0.5f);
  const std::string text = energyCsvText({a, a});
  REQUIRE(text.rfind(kEnergyCsvSignature, 0) == 0);
  size_t cuts = 0;
  for (size_t at = text.find('\n'); at + 1 < text.size(); at = text.find('\n', at + 1), ++cuts) {
    INFO(text.substr(0, at + 1));
    CHECK_FALSE(csvError(text.substr(0, at + 1)).empty());
  }
  CHECK(cuts == 2 + 2 * 5);  // signature, header, per source a direct row and 4 bins
  CHECK(csvError(text).empty());
  CHECK(csvError(text.substr(0, text.rfind("# end"))).find("cut short") != std::string::npos);
  // A row lost in the middle of a source's bins is refused by the bins' times; a whole source's
  // rows lost, or a row after the end, by the end line.
  const std::string sig = std::string(kEnergyCsvSignature) + "\n";
  const std::string oneSource = sig + kHeader + kBins;
  CHECK(csvError(oneSource + "# end: 3 rows\n").find("line 5: the end line counts 3 rows, the "
                                                     "file has 2") != std::string::npos);
  CHECK(csvError(oneSource + "# end: 2 rows\n" + "1,bin,0,1,1,1,1,1,1,1,1\n")
            .find("line 6: a data row after the end line") != std::string::npos);
  CHECK(csvError(oneSource + "# end: two rows\n").find("line 5: the end line must read") !=
        std::string::npos);
  CHECK(csvError(oneSource + "# end: 2 rows\n").empty());
  // v1 (no end line) and unsigned tables are still read.
  CHECK(csvError("# dpc energy response v1: x\n" + kHeader + kBins).empty());
  CHECK(csvError(kHeader + kBins).empty());
}

TEST_CASE("Energy-response CSV: a folder or a FIFO is refused before reading", "[er-out]") {
  const std::string dir = std::string(DPC_BINARY_DIR) + "/energy_csv_dir.csv";
  const std::string fifo = std::string(DPC_BINARY_DIR) + "/energy_csv_fifo.csv";
  std::filesystem::remove_all(dir);
  std::filesystem::remove(fifo);
  std::filesystem::create_directory(dir);
  REQUIRE(::mkfifo(fifo.c_str(), 0600) == 0);
  CHECK_THROWS_WITH(readEnergyCsv(dir), Catch::Contains("is a directory"));
  CHECK_THROWS_WITH(readEnergyCsv(fifo), Catch::Contains("is not a regular file"));  // no hang
  std::filesystem::remove_all(dir);
  std::filesystem::remove(fifo);
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
  // The same table cut short at a line boundary (a copy interrupted, a disk that filled): one
  // line naming the file, a non-zero exit, no analysis printed.
  {
    std::ifstream in(csv);
    std::ofstream cut(dir + "/cut.csv");
    std::string line;
    for (int n = 0; n < 500 && std::getline(in, line); ++n) cut << line << "\n";
  }
  const std::string cutErr = dir + "/cut.err", cutOut = dir + "/cut.out";
  CHECK(std::system((bin + "dpc-analyze " + dir + "/cut.csv >" + cutOut + " 2>" + cutErr)
                        .c_str()) != 0);
  std::stringstream err, out;
  err << std::ifstream(cutErr).rdbuf();
  out << std::ifstream(cutOut).rdbuf();
  CHECK(err.str().find("cut.csv: ends after 498 data rows") != std::string::npos);
  CHECK(out.str().empty());
  // Without --offline: one-line error naming the flag, non-zero exit, no file.
  const std::string live = dir + "/live.csv";
  const int refused =
      std::system((bin + "dpc-demo " + scene + " --er-out " + live + " 2>/dev/null").c_str());
  CHECK(refused != 0);
  CHECK_FALSE(std::ifstream(live).good());
  std::system(("rm -rf " + dir).c_str());
}

namespace {

std::string slurp(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

size_t entriesIn(const std::filesystem::path& dir) {
  size_t n = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir)) ++n;
  return n;
}

}  // namespace

TEST_CASE("Energy-response CSV: a failed write leaves no file and an existing one untouched",
          "[er-out]") {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(DPC_BINARY_DIR) / ("er_atomic_test_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  SourceEnergy a;
  a.energy = EnergyResponse(1.0, 1e-3);  // 1000 bins: about 100 kB of text
  for (size_t k = 0; k < a.energy.binCount(); ++k) a.energy.bins()[k] = Bands(1e-4f);

  // A missing folder: refused naming the path, nothing created.
  const std::string missing = (dir / "missing" / "er.csv").string();
  CHECK_THROWS_WITH(writeEnergyCsv(missing, {a}), Catch::StartsWith(missing + ": cannot write"));
  CHECK(entriesIn(dir) == 0);

  // A write that fails half-way (the file-size limit is hit, as a full disk would be): the error
  // names the path, the temporary is removed, and the file already at the path is untouched.
  const std::string path = (dir / "er.csv").string();
  std::ofstream(path, std::ios::binary) << "an earlier result\n";
  const pid_t child = ::fork();
  REQUIRE(child >= 0);
  if (child == 0) {
    ::signal(SIGXFSZ, SIG_IGN);  // write() then fails with EFBIG instead of killing the process
    const rlimit limit{4096, 4096};
    ::setrlimit(RLIMIT_FSIZE, &limit);
    int code = 1;
    try {
      writeEnergyCsv(path, {a});
      code = 2;  // no error: the limit did not bite
    } catch (const InputError& e) {
      code = std::string(e.what()).rfind(path + ": cannot write", 0) == 0 ? 0 : 3;
    } catch (...) {
      code = 4;
    }
    ::_exit(code);
  }
  int status = 0;
  REQUIRE(::waitpid(child, &status, 0) == child);
  REQUIRE(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 0);
  CHECK(slurp(path) == "an earlier result\n");
  CHECK(entriesIn(dir) == 1);

  // A successful write replaces it, leaving no temporary behind.
  writeEnergyCsv(path, {a});
  REQUIRE(readEnergyCsv(path).size() == 1);
  CHECK(entriesIn(dir) == 1);
  fs::remove_all(dir);
}
