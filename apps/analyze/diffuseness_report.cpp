// dpc-analyze IR.wav --diffuseness N: the late part's diffuseness of an AmbiX impulse response
// per octave band (analysis/ambisonic_diffuseness.h). Channels are read in blocks of
// (N + 1)^2: one, or one per source in the source-major order of dpc-demo --ir-out.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include "analysis/ambisonic_diffuseness.h"
#include "apps/analyze/options.h"
#include "apps/analyze/report.h"
#include "audio/wav_io.h"

namespace dpc::analyze {
namespace {

using audio::AmbisonicDiffuseness;

void printRow(const char* label, const std::array<double, kNumBands>& bands, double broadband) {
  std::string line = label;
  line.resize(kLabel, ' ');
  for (int b = 0; b < kNumBands; ++b) line += pad(cell(bands[size_t(b)], 2), kColumn);
  line += pad(cell(broadband, 2), kColumn + 2);
  std::printf("%s\n", line.c_str());
}

void printTable(const std::string& file, size_t first, size_t count,
                const AmbisonicDiffuseness& a) {
  std::printf("%s: late-part diffuseness (80 ms after the direct sound on), channels %zu-%zu\n",
              file.c_str(), first + 1, first + count);
  std::string header(kLabel, ' ');
  for (int b = 0; b < kNumBands; ++b)
    header += pad(std::to_string(int(kBandCentreHz[size_t(b)])), kColumn);
  std::printf("%s%s\n", header.c_str(), pad("broadband", kColumn + 2).c_str());
  printRow("DirAC", a.dirac, a.broadbandDirac);
  printRow("COMEDIE", a.comedie, a.broadbandComedie);
}

nlohmann::ordered_json value(double v) {
  return std::isnan(v) ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(v);
}

nlohmann::ordered_json toJson(size_t first, size_t count, const AmbisonicDiffuseness& a) {
  nlohmann::ordered_json bands = nlohmann::ordered_json::array();
  for (int b = 0; b < kNumBands; ++b)
    bands.push_back({{"centreHz", kBandCentreHz[size_t(b)]},
                     {"dirac", value(a.dirac[size_t(b)])},
                     {"comedie", value(a.comedie[size_t(b)])}});
  return {{"firstChannel", first + 1},
          {"channels", count},
          {"onsetSeconds", value(a.onsetSeconds)},
          {"bands", bands},
          {"broadband", {{"dirac", value(a.broadbandDirac)}, {"comedie", value(a.broadbandComedie)}}}};
}

}  // namespace

int analyzeDiffuseness(const Options& o, const audio::AudioData& ir) {
  const int order = o.diffusenessOrder;
  const size_t block = size_t((order + 1) * (order + 1)), channels = ir.channels.size();
  if (channels == 0 || channels % block != 0) {
    std::cerr << o.file << ": --diffuseness: an order-" << order << " AmbiX IR has channels in "
              << "blocks of " << block << "; the file has " << channels << "\n";
    return 1;
  }
  nlohmann::ordered_json blocks = nlohmann::ordered_json::array();
  for (size_t first = 0; first < channels; first += block) {
    std::vector<const float*> p;
    for (size_t c = first; c < first + block; ++c) p.push_back(ir.channels[c].data());
    const AmbisonicDiffuseness a =
        audio::analyzeAmbisonicDiffuseness(p, order, ir.frames(), ir.sampleRate);
    if (o.json) {
      blocks.push_back(toJson(first, block, a));
    } else {
      if (first > 0) std::printf("\n");
      printTable(o.file, first, block, a);
    }
  }
  if (o.json)
    std::cout << dumpJson({{"file", o.file}, {"sampleRate", ir.sampleRate}, {"order", order},
                           {"sources", blocks}})
              << "\n";
  return 0;
}

}  // namespace dpc::analyze
