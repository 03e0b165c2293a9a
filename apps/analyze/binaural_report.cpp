// dpc-analyze IR.wav --iacc: the interaural cross-correlation of a binaural impulse response
// per octave band (ISO 3382-1 Annex B; analysis/interaural_correlation.h). Channels are read
// as (left, right) pairs: one pair, or one per source in the source-major order of dpc-demo
// --ir-out.
#include <cstdio>
#include <iostream>
#include <string>

#include "analysis/interaural_correlation.h"
#include "apps/analyze/options.h"
#include "apps/analyze/report.h"
#include "audio/wav_io.h"
#include "common/input_error.h"

namespace dpc::analyze {
namespace {

using audio::BinauralAnalysis;
using audio::InterauralCorrelation;

/// The means over the 500 Hz, 1 kHz and 2 kHz bands (IACC_E3, IACC_L3: Hidaka et al. 1995).
InterauralCorrelation threeBandMean(const BinauralAnalysis& a) {
  InterauralCorrelation m{0.0, 0.0, 0.0};
  for (int b : {3, 4, 5}) {
    m.early += a.bands[size_t(b)].early / 3.0;
    m.late += a.bands[size_t(b)].late / 3.0;
    m.all += a.bands[size_t(b)].all / 3.0;
  }
  return m;
}

void printRow(const char* label, const BinauralAnalysis& a, double InterauralCorrelation::*w) {
  std::string line = label;
  line.resize(kLabel, ' ');
  for (int b = 0; b < kNumBands; ++b) line += pad(cell(a.bands[size_t(b)].*w, 2), kColumn);
  line += pad(cell(a.broadband.*w, 2), kColumn + 2);
  line += pad(cell(threeBandMean(a).*w, 2), kColumn + 2);
  std::printf("%s\n", line.c_str());
}

void printIaccTable(const std::string& file, size_t pair, const BinauralAnalysis& a) {
  std::printf("%s: interaural cross-correlation, channel %zu = left ear, %zu = right ear\n",
              file.c_str(), 2 * pair + 1, 2 * pair + 2);
  std::string header(kLabel, ' ');
  for (int b = 0; b < kNumBands; ++b)
    header += pad(std::to_string(int(kBandCentreHz[size_t(b)])), kColumn);
  header += pad("broadband", kColumn + 2) + pad("500-2k", kColumn + 2);
  std::printf("%s\n", header.c_str());
  printRow("IACC_E", a, &InterauralCorrelation::early);
  printRow("IACC_L", a, &InterauralCorrelation::late);
  printRow("IACC_A", a, &InterauralCorrelation::all);
}

nlohmann::ordered_json toJson(const InterauralCorrelation& c) {
  auto value = [](double v) -> nlohmann::ordered_json {
    return std::isnan(v) ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(v);
  };
  return {{"iaccE", value(c.early)}, {"iaccL", value(c.late)}, {"iaccA", value(c.all)}};
}

nlohmann::ordered_json iaccJson(size_t pair, const BinauralAnalysis& a) {
  nlohmann::ordered_json bands = nlohmann::ordered_json::array();
  for (int b = 0; b < kNumBands; ++b) {
    nlohmann::ordered_json entry = {{"centreHz", kBandCentreHz[size_t(b)]}};
    entry.update(toJson(a.bands[size_t(b)]));
    bands.push_back(entry);
  }
  return {{"left", 2 * pair + 1},
          {"right", 2 * pair + 2},
          {"onsetSeconds", a.onsetSeconds},
          {"bands", bands},
          {"broadband", toJson(a.broadband)},
          {"mean500to2000", toJson(threeBandMean(a))}};
}

}  // namespace

int analyzeInterauralCorrelation(const Options& o, const audio::AudioData& ir) {
  const size_t channels = ir.channels.size();
  if (channels == 0 || channels % 2 != 0) {
    std::cerr << o.file << ": --iacc: needs a binaural IR, channels in (left, right) pairs; the "
              << "file has " << channels << "\n";
    return 1;
  }
  nlohmann::ordered_json pairs = nlohmann::ordered_json::array();
  for (size_t p = 0; p < channels / 2; ++p) {
    const BinauralAnalysis a = audio::analyzeBinaural(
        ir.channels[2 * p].data(), ir.channels[2 * p + 1].data(), ir.frames(), ir.sampleRate);
    if (o.json) {
      pairs.push_back(iaccJson(p, a));
    } else {
      if (p > 0) std::printf("\n");
      printIaccTable(o.file, p, a);
    }
  }
  if (o.json)
    std::cout << dumpJson({{"file", o.file}, {"sampleRate", ir.sampleRate}, {"pairs", pairs}})
              << "\n";
  return 0;
}

}  // namespace dpc::analyze
