// dpc-analyze ER.csv: room parameters or band energies of an energy response exported by
// dpc-demo --er-out, one table per source.
#include <cstdio>
#include <iostream>

#include "analysis/energy_response_csv.h"
#include "analysis/room_parameters.h"
#include "apps/analyze/options.h"
#include "apps/analyze/report.h"
#include "scene/scene.h"
#include "analysis/expected_band_analysis.h"

namespace dpc::analyze {
namespace {

using audio::ImpulseResponseAnalysis;

/// Band energies per bin of one source of an energy-response CSV: the response with its direct
/// sound in its bin, or (asMeasured) what the band analysis of an exact IR of it reads.
std::array<std::vector<double>, kNumBands> sourceBandEnergy(const SourceEnergy& s,
                                                            bool asMeasured) {
  return asMeasured ? expectedBandAnalysisEnergy(s.energy, s.direct, AudioSettings{}.sampleRate)
                    : withDirect(s);
}

/// Per-band parameters of one source of an energy-response CSV (dpc-demo --er-out); the
/// "broadband" column weighs the bands by their shares of a white spectrum at the default
/// scene sample rate (common/bands.h whiteSpectrumShares): the energy an IR of it carries.
/// asMeasured: the bands are what the ISO band analysis reads, in expectation, from an IR that
/// carries the response (dpc::expectedBandAnalysisEnergy at the default scene sample rate); the
/// broadband column is the same weighted sum of the response's bands either way.
ImpulseResponseAnalysis analyzeSource(const SourceEnergy& s, bool asMeasured) {
  ImpulseResponseAnalysis a;
  const auto bands = withDirect(s);
  const auto measured = asMeasured ? sourceBandEnergy(s, true) : bands;
  std::vector<double> sum(bands[0].size(), 0.0);
  const double t0 = onsetSecondsOf(s.direct), bin = s.energy.binSeconds();
  // Band values are spectral densities: the broadband energy weighs each by its share of a
  // white spectrum, as an IR synthesised from the response carries them.
  const auto share = whiteSpectrumShares(double(AudioSettings{}.sampleRate));
  for (int b = 0; b < kNumBands; ++b) {
    const auto& e = measured[size_t(b)];
    a.bands[size_t(b)] = audio::analyzeEnergyDecay(e.data(), e.size(), bin, t0);
    for (size_t k = 0; k < e.size(); ++k) sum[k] += share[size_t(b)] * bands[size_t(b)][k];
  }
  a.broadband = audio::analyzeEnergyDecay(sum.data(), sum.size(), bin, t0);
  return a;
}

/// --as-measured needs bins of at least one sample at the default sample rate; false (with
/// one line on stderr) otherwise.
bool binsFitAsMeasured(const std::string& file, const std::vector<SourceEnergy>& sources) {
  for (const auto& src : sources)
    if (!(src.energy.binSeconds() * AudioSettings{}.sampleRate >= 1.0)) {
      std::cerr << "dpc-analyze: --as-measured: " << file << ": bins of " << src.energy.binSeconds()
                << " s are shorter than one sample at " << AudioSettings{}.sampleRate << " Hz\n";
      return false;
    }
  return true;
}

/// The parameters of every source: a table each, or one JSON document.
void printParameters(const Options& o, const std::vector<SourceEnergy>& sources) {
  nlohmann::ordered_json out = {{"file", o.file},
                                {"bandCentresHz", kBandCentreHz},
                                {"sources", nlohmann::ordered_json::array()}};
  for (size_t s = 0; s < sources.size(); ++s) {
    const ImpulseResponseAnalysis a = analyzeSource(sources[s], o.asMeasured);
    if (o.json) {
      nlohmann::ordered_json entry = {{"source", s}};
      entry.update(analysisJson(a));
      out["sources"].push_back(entry);
    } else {
      if (s != 0) std::printf("\n");
      char title[256];
      std::snprintf(title, sizeof title, "%s: source %zu of %zu, energy response%s, %.3f s",
                    o.file.c_str(), s, sources.size(), o.asMeasured ? " as measured" : "",
                    double(sources[s].energy.binCount()) * sources[s].energy.binSeconds());
      printTable(title, a);
    }
  }
  if (o.json) std::cout << dumpJson(out) << "\n";
}

}  // namespace

int analyzeEnergyResponse(const Options& o) {
  if (!o.channelText.empty()) {
    std::cerr << "dpc-analyze: --channel: " << o.file
              << ": an energy-response CSV has sources, not channels (all are analysed)\n";
    return 1;
  }
  const auto sources = readEnergyCsv(o.file);
  if (o.asMeasured && !binsFitAsMeasured(o.file, sources)) return 1;
  if (o.bandEnergy) {
    printBandEnergyHeader(o.file, "source");
    for (size_t s = 0; s < sources.size(); ++s)
      printBandEnergy(s, 0.0, sources[s].energy.binSeconds(),
                      sourceBandEnergy(sources[s], o.asMeasured));
    return 0;
  }
  printParameters(o, sources);
  return 0;
}

}  // namespace dpc::analyze
