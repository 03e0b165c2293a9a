// dpc-analyze: ISO 3382-1 room acoustic parameters of an impulse-response WAV file or of an
// energy response exported by dpc-demo --er-out (a .csv file).
//
//   dpc-analyze IR.wav|ER.csv [--json] [--channel N]
//   dpc-analyze --air-attenuation T RH [--json]
//
// Per channel (WAV) or source (CSV): T20, T30, EDT (s), C50, C80 (dB), D50 (%) and strength
// G (dB, relative to the free-field direct sound at 10 m on dpc's energy scale) in the octave
// bands 63 Hz .. 8 kHz and broadband (see analysis/room_parameters.h for the method). Control thread
// only. Bad input prints one line "FILE: FIELD: problem" on stderr and exits with status 1.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>

#include "analysis/expected_band_analysis.h"
#include "analysis/room_parameters.h"
#include "audio/wav_io.h"
#include "common/air_absorption.h"
#include "common/bands.h"
#include "analysis/energy_response_csv.h"
#include "common/input_error.h"
#include "scene/scene.h"

namespace {

using dpc::kNumBands;
using dpc::audio::AudioData;
using dpc::audio::ImpulseResponseAnalysis;
using dpc::audio::RoomParameters;

// Parses "--channel" (1-based) against the file's channel count.
size_t parseChannel(const std::string& file, const std::string& text, size_t channels) {
  size_t used = 0;
  long value = 0;
  try {
    value = std::stol(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size())
    throw dpc::InputError(file, "--channel", "'" + text + "' is not a whole number");
  if (value < 1 || size_t(value) > channels)
    throw dpc::InputError(file, "--channel",
                          std::to_string(value) + " is out of range: the file has " +
                              std::to_string(channels) + " channel" + (channels == 1 ? "" : "s") +
                              " (1.." + std::to_string(channels) + ")");
  return size_t(value - 1);
}

// Table cell: "—" for NaN (not measurable), "+inf"/"-inf" for unbounded ratios.
std::string cell(double v, int decimals) {
  if (std::isnan(v)) return "—";
  if (std::isinf(v)) return v > 0 ? "+inf" : "-inf";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

// Right-aligns to `width` display columns (the em dash is one column but three bytes).
std::string pad(const std::string& s, size_t width) {
  size_t columns = 0;
  for (unsigned char c : s) columns += (c & 0xC0) != 0x80;  // count UTF-8 lead bytes
  return std::string(width > columns ? width - columns : 0, ' ') + s;
}

double strength(const RoomParameters& r) {
  return dpc::audio::strengthDb(r.energy);
}

void printTable(const std::string& title, const ImpulseResponseAnalysis& a) {
  std::printf("%s\n", title.c_str());
  constexpr size_t kLabel = 10, kColumn = 8;
  std::string header = std::string(kLabel, ' ');
  for (int b = 0; b < kNumBands; ++b)
    header += pad(std::to_string(int(dpc::kBandCentreHz[size_t(b)])), kColumn);
  header += pad("broadband", kColumn + 2);
  std::printf("%s\n", header.c_str());
  struct Row {
    const char* label;
    double RoomParameters::*field;
    double scale;
    int decimals;
  };
  const Row rows[] = {
      {"T20 (s)", &RoomParameters::t20, 1.0, 2},  {"T30 (s)", &RoomParameters::t30, 1.0, 2},
      {"EDT (s)", &RoomParameters::edt, 1.0, 2},  {"C50 (dB)", &RoomParameters::c50, 1.0, 1},
      {"C80 (dB)", &RoomParameters::c80, 1.0, 1}, {"D50 (%)", &RoomParameters::d50, 100.0, 0}};
  for (const Row& row : rows) {
    std::string line = row.label;
    line.resize(kLabel, ' ');
    for (int b = 0; b < kNumBands; ++b)
      line += pad(cell(a.bands[size_t(b)].*row.field * row.scale, row.decimals), kColumn);
    line += pad(cell(a.broadband.*row.field * row.scale, row.decimals), kColumn + 2);
    std::printf("%s\n", line.c_str());
  }
  std::string line = "G (dB)";
  line.resize(kLabel, ' ');
  for (int b = 0; b < kNumBands; ++b) line += pad(cell(strength(a.bands[size_t(b)]), 1), kColumn);
  line += pad(cell(strength(a.broadband), 1), kColumn + 2);
  std::printf("%s\n", line.c_str());
}

bool endsWith(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() &&
         std::equal(tail.rbegin(), tail.rend(), s.rbegin(), [](char a, char b) {
           return std::tolower(static_cast<unsigned char>(a)) == b;
         });
}

/// --band-energy bins for an IR, seconds (the energy response's usual resolution).
constexpr double kBandEnergyBinSeconds = 1e-3;

/// The --band-energy table's comment line and header.
void printBandEnergyHeader(const std::string& file, const char* index) {
  std::printf("# dpc-analyze --band-energy: %s\n%s,time_s", file.c_str(), index);
  for (int b = 0; b < kNumBands; ++b) std::printf(",%g", dpc::kBandCentreHz[size_t(b)]);
  std::printf("\n");
}

/// One --band-energy table row per bin: `index,time_s,<energy per band>`; a band without
/// values (above Nyquist) leaves its cells empty.
void printBandEnergy(size_t index, double start, double binSeconds,
                     const std::array<std::vector<double>, kNumBands>& energy) {
  size_t rows = 0;
  for (const auto& e : energy) rows = std::max(rows, e.size());
  for (size_t k = 0; k < rows; ++k) {
    std::printf("%zu,%.6f", index, start + double(k) * binSeconds);
    for (const auto& e : energy) {
      if (k < e.size())
        std::printf(",%.9g", e[k]);
      else
        std::printf(",");
    }
    std::printf("\n");
  }
}

/// Band energies per bin of one source of an energy-response CSV: the response with its direct
/// sound in its bin, or (asMeasured) what the band analysis of an exact IR of it reads.
std::array<std::vector<double>, kNumBands> sourceBandEnergy(const dpc::SourceEnergy& s,
                                                            bool asMeasured) {
  return asMeasured ? dpc::expectedBandAnalysisEnergy(s.energy, s.direct,
                                                      dpc::AudioSettings{}.sampleRate)
                    : dpc::withDirect(s);
}

/// Per-band parameters of one source of an energy-response CSV (dpc-demo --er-out); the
/// "broadband" column sums the bands.
/// asMeasured: the bands are what the ISO band analysis reads, in expectation, from an IR that
/// carries the response (dpc::expectedBandAnalysisEnergy at the default scene sample rate); the
/// broadband column is the same sum of the response's bands either way.
ImpulseResponseAnalysis analyzeSource(const dpc::SourceEnergy& s, bool asMeasured) {
  ImpulseResponseAnalysis a;
  const auto bands = dpc::withDirect(s);
  const auto measured = asMeasured ? sourceBandEnergy(s, true) : bands;
  std::vector<double> sum(bands[0].size(), 0.0);
  for (int b = 0; b < kNumBands; ++b) {
    const auto& e = measured[size_t(b)];
    a.bands[size_t(b)] = dpc::audio::analyzeEnergyDecay(e.data(), e.size(), s.energy.binSeconds());
    for (size_t k = 0; k < e.size(); ++k) sum[k] += bands[size_t(b)][k];
  }
  a.broadband = dpc::audio::analyzeEnergyDecay(sum.data(), sum.size(), s.energy.binSeconds());
  return a;
}

/// JSON text of `j`; bytes of a file name that are not UTF-8 become U+FFFD instead of making
/// the JSON library throw (file names on Linux are bytes, not text).
std::string dumpJson(const nlohmann::ordered_json& j) {
  return j.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace);
}

nlohmann::ordered_json toJson(double v) {
  if (std::isnan(v)) return nullptr;
  if (std::isinf(v)) return v > 0 ? "+inf" : "-inf";
  return v;
}

nlohmann::ordered_json toJson(const RoomParameters& r) {
  return {{"t20", toJson(r.t20)},    {"t30", toJson(r.t30)}, {"edt", toJson(r.edt)},
          {"c50", toJson(r.c50)},    {"c80", toJson(r.c80)}, {"d50", toJson(r.d50)},
          {"g", toJson(strength(r))}};
}

/// Per-band parameters and the broadband ones, keyed by band centre.
nlohmann::ordered_json analysisJson(const ImpulseResponseAnalysis& a) {
  nlohmann::ordered_json bands = nlohmann::ordered_json::array();
  for (int b = 0; b < kNumBands; ++b) {
    nlohmann::ordered_json entry = {{"centreHz", dpc::kBandCentreHz[size_t(b)]}};
    entry.update(toJson(a.bands[size_t(b)]));
    bands.push_back(entry);
  }
  return {{"bands", bands}, {"broadband", toJson(a.broadband)}};
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "dpc-analyze: ISO 3382-1 room acoustic parameters of an impulse response.\n"
      "Reads a WAV IR, or an energy-response CSV from dpc-demo --er-out (by its .csv name).\n"
      "Prints per channel T20, T30, EDT (s), C50, C80 (dB), D50 (%) and G (dB re the free\n"
      "field at 10 m, dpc's scale: 1/(4 pi 100) relative to source power) in the octave bands\n"
      "63 Hz .. 8 kHz and broadband, from Schroeder backward integration (ISO 3382-1:2009).\n"
      "'—' (JSON: null) marks a value the IR cannot give, e.g. T30 when the decay is not\n"
      "recorded 10 dB below -35 dB, or a band above Nyquist. C50/C80 are +inf when no energy\n"
      "arrives late (JSON: the string \"+inf\"). JSON gives D50 as a ratio 0..1.\n"
      "Exit status: 0 on success, 1 on bad input (message on stderr).",
      "dpc-analyze"};
  std::string file;
  bool json = false;
  std::string channelText;
  std::vector<double> air;
  auto* irOption =
      app.add_option("IR", file, "Impulse response file (WAV or anything libsndfile reads)")
          ->type_name("FILE");
  app.add_option("--air-attenuation", air,
                 "Instead of analysing: print the ISO 9613-1 air attenuation per octave band that "
                 "dpc applies at this temperature (degrees C, -50..60) and relative humidity "
                 "(%, 0..100), as energy attenuation m (1/m) and dB/km")
      ->expected(2)
      ->type_name("T RH")
      ->excludes(irOption);
  app.add_flag("--json", json, "Print JSON instead of tables");
  bool asMeasured = false;
  app.add_flag("--as-measured", asMeasured,
               "For an energy-response CSV: the band parameters that the ISO 3382-1 band "
               "analysis of an IR carrying this response would give (expected values at 48 kHz: "
               "the octave filters' delay, skirts and noise bandwidth included), for comparison "
               "with parameters measured from real IRs");
  bool bandEnergy = false;
  app.add_flag("--band-energy", bandEnergy,
               "Instead of parameters: print CSV rows `index,time_s,<8 bands>` under a header "
               "`channel|source,time_s,63,...,8000`: the energy "
               "per octave band in time bins (1/m^2 on dpc's scale), for plotting decay curves. "
               "WAV: channel (1 = first), 1 ms bins from the broadband onset, through the ISO "
               "analysis filters; energy-response CSV: source (0 = first), the response's own "
               "bins from emission, the direct sound in its bin (with --as-measured: what an "
               "exact IR's band analysis reads)")
      ->excludes("--json");
  app.add_option("--channel", channelText, "Analyse only channel N (1 = first; default: all)")
      ->type_name("N");
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << "dpc-analyze: " << e.what() << " (see --help)\n";
    return 1;
  }

  if (!air.empty()) {
    const double t = air[0], rh = air[1];
    if (!(t >= -50.0 && t <= 60.0) || !(rh >= 0.0 && rh <= 100.0)) {
      std::cerr << "dpc-analyze: --air-attenuation: temperature must be in [-50, 60] C and "
                   "humidity in [0, 100] %\n";
      return 1;
    }
    const dpc::Bands m = dpc::airEnergyAttenuationPerMetre(t, rh);
    nlohmann::ordered_json out = {{"temperatureC", t},
                                  {"humidityPercent", rh},
                                  {"bandCentresHz", dpc::kBandCentreHz},
                                  {"energyAttenuationPerMetre", nlohmann::ordered_json::array()}};
    for (int b = 0; b < dpc::kNumBands; ++b) out["energyAttenuationPerMetre"].push_back(m[b]);
    if (json) {
      std::cout << dumpJson(out) << "\n";
    } else {
      std::printf("air attenuation at %.1f C, %.1f %% RH (ISO 9613-1)\n", t, rh);
      for (int b = 0; b < dpc::kNumBands; ++b)
        std::printf("  %5.0f Hz  m = %.3e 1/m  (%.2f dB/km)\n", dpc::kBandCentreHz[size_t(b)],
                    double(m[b]), double(m[b]) * 10.0 / std::log(10.0) * 1000.0);
    }
    return 0;
  }
  if (file.empty()) {
    std::cerr << "dpc-analyze: IR: an impulse response file is required (see --help)\n";
    return 1;
  }
  try {
    if (asMeasured && !endsWith(file, ".csv")) {
      std::cerr << "dpc-analyze: --as-measured: " << file
                << ": needs an energy-response CSV from dpc-demo --er-out (an IR is already "
                   "measured)\n";
      return 1;
    }
    if (endsWith(file, ".csv") && !channelText.empty()) {
      std::cerr << "dpc-analyze: --channel: " << file
                << ": an energy-response CSV has sources, not channels (all are analysed)\n";
      return 1;
    }
    if (endsWith(file, ".csv")) {
      // An energy response written by dpc-demo --er-out: one table per source.
      const auto sources = dpc::readEnergyCsv(file);
      if (asMeasured)
        for (const auto& src : sources)
          if (!(src.energy.binSeconds() * dpc::AudioSettings{}.sampleRate >= 1.0)) {
            std::cerr << "dpc-analyze: --as-measured: " << file << ": bins of "
                      << src.energy.binSeconds() << " s are shorter than one sample at "
                      << dpc::AudioSettings{}.sampleRate << " Hz\n";
            return 1;
          }
      if (bandEnergy) {
        printBandEnergyHeader(file, "source");
        for (size_t s = 0; s < sources.size(); ++s)
          printBandEnergy(s, 0.0, sources[s].energy.binSeconds(),
                          sourceBandEnergy(sources[s], asMeasured));
        return 0;
      }
      nlohmann::ordered_json out = {{"file", file},
                                    {"bandCentresHz", dpc::kBandCentreHz},
                                    {"sources", nlohmann::ordered_json::array()}};
      for (size_t s = 0; s < sources.size(); ++s) {
        const ImpulseResponseAnalysis a = analyzeSource(sources[s], asMeasured);
        if (json) {
          nlohmann::ordered_json entry = {{"source", s}};
          entry.update(analysisJson(a));
          out["sources"].push_back(entry);
        } else {
          if (s != 0) std::printf("\n");
          char title[256];
          std::snprintf(title, sizeof title, "%s: source %zu of %zu, energy response%s, %.3f s",
                        file.c_str(), s, sources.size(), asMeasured ? " as measured" : "",
                        double(sources[s].energy.binCount()) * sources[s].energy.binSeconds());
          printTable(title, a);
        }
      }
      if (json) std::cout << dumpJson(out) << "\n";
      return 0;
    }
    const AudioData audio = dpc::audio::readWav(file);
    size_t first = 0, last = audio.channels.size();
    if (!channelText.empty()) {
      first = parseChannel(file, channelText, audio.channels.size());
      last = first + 1;
    }
    // A NaN or infinite sample would turn every parameter into '—': refuse it by name.
    for (size_t c = first; c < last; ++c)
      for (size_t n = 0; n < audio.frames(); ++n)
        if (!std::isfinite(audio.channels[c][n])) {
          std::cerr << file << ": sample " << n << " (0 = first) of channel " << c + 1
                    << " is not finite (NaN or infinity)\n";
          return 1;
        }
    if (bandEnergy) {
      printBandEnergyHeader(file, "channel");
      for (size_t c = first; c < last; ++c) {
        const auto& samples = audio.channels[c];
        const dpc::audio::BandEnergyBins e = dpc::audio::bandEnergyBins(
            samples.data(), samples.size(), audio.sampleRate, kBandEnergyBinSeconds);
        printBandEnergy(c + 1, e.onsetSeconds, e.binSeconds, e.energy);
      }
      return 0;
    }
    nlohmann::ordered_json out;
    if (json) {
      out = {{"file", file},
             {"sampleRate", audio.sampleRate},
             {"frames", audio.frames()},
             {"bandCentresHz", dpc::kBandCentreHz},
             {"channels", nlohmann::ordered_json::array()}};
    }
    for (size_t c = first; c < last; ++c) {
      const auto& samples = audio.channels[c];
      const ImpulseResponseAnalysis a =
          dpc::audio::analyzeImpulseResponse(samples.data(), samples.size(), audio.sampleRate);
      if (json) {
        nlohmann::ordered_json entry = {{"channel", c + 1}};
        entry.update(analysisJson(a));
        out["channels"].push_back(entry);
      } else {
        if (c != first) std::printf("\n");
        char title[256];
        std::snprintf(title, sizeof title, "%s: channel %zu of %zu, %d Hz, %.3f s", file.c_str(),
                      c + 1, audio.channels.size(), audio.sampleRate,
                      double(audio.frames()) / double(audio.sampleRate));
        printTable(title, a);
      }
    }
    if (json) std::cout << dumpJson(out) << "\n";
  } catch (const dpc::InputError& e) {
    std::cerr << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << file << ": " << e.what() << "\n";
    return 1;
  }
  return 0;
}
