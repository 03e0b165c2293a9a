// dpc-analyze IR.wav: room parameters or band energies of an impulse response, per channel.
#include <cmath>
#include <cstdio>
#include <iostream>

#include "analysis/room_parameters.h"
#include "apps/analyze/options.h"
#include "apps/analyze/report.h"
#include "audio/wav_io.h"
#include "common/input_error.h"
#include "common/input_file.h"

namespace dpc::analyze {
namespace {

using audio::AudioData;
using audio::ImpulseResponseAnalysis;

/// --band-energy bins for an IR, seconds (the energy response's usual resolution).
constexpr double kBandEnergyBinSeconds = 1e-3;

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
    throw InputError(file, "--channel", "'" + text + "' is not a whole number");
  if (value < 1 || size_t(value) > channels)
    throw InputError(file, "--channel",
                     std::to_string(value) + " is out of range: the file has " +
                         std::to_string(channels) + " channel" + (channels == 1 ? "" : "s") +
                         " (1.." + std::to_string(channels) + ")");
  return size_t(value - 1);
}

/// A NaN or infinite sample, a silent channel or a sample rate no signal has (those of a dry
/// signal: common/input_file.h) would turn every parameter into '—' or nonsense: refuses it by
/// name (one line on stderr, false).
bool samplesFinite(const std::string& file, const AudioData& ir, size_t first, size_t last) {
  if (ir.sampleRate < kMinSignalRateHz || ir.sampleRate > kMaxSignalRateHz) {
    std::cerr << file << ": sample rate " << ir.sampleRate << " Hz is outside ["
              << kMinSignalRateHz << ", " << kMaxSignalRateHz << "] Hz\n";
    return false;
  }
  bool silent = true;  // a silent channel beside others (an AmbiX Y of a source ahead) is read
  for (size_t c = first; c < last; ++c)
    for (size_t n = 0; n < ir.frames(); ++n) {
      if (!std::isfinite(ir.channels[c][n])) {
        std::cerr << file << ": sample " << n << " (0 = first) of channel " << c + 1
                  << " is not finite (NaN or infinity)\n";
        return false;
      }
      silent = silent && ir.channels[c][n] == 0.f;
    }
  if (silent)
    std::cerr << file << ": " << (last - first == 1 ? "the channel" : "every channel")
              << " analysed is silent (every sample 0): an impulse response without sound has "
                 "no room parameters\n";
  return !silent;
}

/// The parameters of channels [first, last): a table each, or one JSON document.
void printParameters(const Options& o, const AudioData& ir, size_t first, size_t last) {
  nlohmann::ordered_json out;
  if (o.json) {
    out = {{"file", o.file},
           {"sampleRate", ir.sampleRate},
           {"frames", ir.frames()},
           {"bandCentresHz", kBandCentreHz},
           {"channels", nlohmann::ordered_json::array()}};
  }
  for (size_t c = first; c < last; ++c) {
    const auto& samples = ir.channels[c];
    const ImpulseResponseAnalysis a =
        audio::analyzeImpulseResponse(samples.data(), samples.size(), ir.sampleRate);
    if (o.json) {
      nlohmann::ordered_json entry = {{"channel", c + 1}};
      entry.update(analysisJson(a));
      out["channels"].push_back(entry);
    } else {
      if (c != first) std::printf("\n");
      char title[256];
      std::snprintf(title, sizeof title, "%s: channel %zu of %zu, %d Hz, %.3f s", o.file.c_str(),
                    c + 1, ir.channels.size(), ir.sampleRate,
                    double(ir.frames()) / double(ir.sampleRate));
      printTable(title, a);
    }
  }
  if (o.json) std::cout << dumpJson(out) << "\n";
}

}  // namespace

int analyzeImpulseResponse(const Options& o) {
  const AudioData ir = audio::readWav(o.file);
  size_t first = 0, last = ir.channels.size();
  if (!o.channelText.empty()) {
    first = parseChannel(o.file, o.channelText, ir.channels.size());
    last = first + 1;
  }
  if (!samplesFinite(o.file, ir, first, last)) return 1;
  if (o.iacc) return analyzeInterauralCorrelation(o, ir);
  if (o.diffusenessOrder > 0) return analyzeDiffuseness(o, ir);
  if (o.bandEnergy) {
    printBandEnergyHeader(o.file, "channel");
    for (size_t c = first; c < last; ++c) {
      const auto& samples = ir.channels[c];
      const audio::BandEnergyBins e = audio::bandEnergyBins(samples.data(), samples.size(),
                                                            ir.sampleRate, kBandEnergyBinSeconds);
      printBandEnergy(c + 1, e.onsetSeconds, e.binSeconds, e.energy);
    }
    return 0;
  }
  printParameters(o, ir, first, last);
  return 0;
}

}  // namespace dpc::analyze
