#include "apps/studio/studio_ir.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <nlohmann/json.hpp>

#include "analysis/interaural_correlation.h"

namespace dpc::studio {
namespace {

using nlohmann::json;

/// A number, or null when it is not finite (JSON has no NaN).
json number(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

json correlationJson(const audio::InterauralCorrelation& c) {
  return {{"early", number(c.early)}, {"late", number(c.late)}, {"all", number(c.all)}};
}

/// IACC of the two ears, as dpc-analyze --iacc computes it from the WAV of the same samples.
json iaccJson(const ImpulseResponse& ir) {
  const audio::BinauralAnalysis a = audio::analyzeBinaural(
      ir.channel(0), ir.channel(1), ir.samples(), int(std::lround(ir.sampleRate())));
  json bands = json::array();
  for (const auto& b : a.bands) bands.push_back(correlationJson(b));
  return {{"onsetSeconds", number(a.onsetSeconds)},
          {"bands", bands},
          {"broadband", correlationJson(a.broadband)}};
}

/// The least and greatest sample of each of kIrColumns spans of `x`.
void columnExtremes(const float* x, size_t n, size_t span, json& lo, json& hi) {
  lo = json::array();
  hi = json::array();
  for (size_t from = 0; from < n; from += span) {
    const auto [mn, mx] = std::minmax_element(x + from, x + std::min(n, from + span));
    lo.push_back(*mn);
    hi.push_back(*mx);
  }
}

/// 10 log10 of each bin's energy relative to the greatest bin; null for an empty bin.
json envelopeDb(const float* x, size_t n, size_t bin) {
  std::vector<double> e;
  for (size_t from = 0; from < n; from += bin) {
    double sum = 0.0;
    for (size_t k = from; k < std::min(n, from + bin); ++k) sum += double(x[k]) * x[k];
    e.push_back(sum);
  }
  const double top = e.empty() ? 0.0 : *std::max_element(e.begin(), e.end());
  json db = json::array();
  for (double v : e) db.push_back(v > 0.0 && top > 0.0 ? json(10.0 * std::log10(v / top)) : json());
  return db;
}

static_assert(std::endian::native == std::endian::little, "irWav writes native floats");

template <class T>
void put(std::string& out, T v) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &v, sizeof(T));  // WAV is little-endian, as this machine (above)
  out.append(bytes, sizeof(T));
}

}  // namespace

std::string irJson(const StudioIr& r) {
  const ImpulseResponse& ir = r.ir;
  const size_t span = std::max<size_t>(1, (ir.samples() + kIrColumns - 1) / kIrColumns);
  const size_t bin = std::max<size_t>(1, size_t(std::lround(kIrEnvelopeBinSeconds * ir.sampleRate())));
  json lo = json::array(), hi = json::array(), env = json::array();
  for (int c = 0; c < std::min(ir.channels(), kIrChannelsDrawn); ++c) {
    json l, h;
    columnExtremes(ir.channel(c), ir.samples(), span, l, h);
    lo.push_back(std::move(l));
    hi.push_back(std::move(h));
    env.push_back(envelopeDb(ir.channel(c), ir.samples(), bin));
  }
  const bool iacc = r.binaural && ir.channels() == 2 && ir.samples() > 0;
  return json{{"frame", r.frame},          {"source", r.source},
              {"sampleRate", ir.sampleRate()}, {"channels", ir.channels()},
              {"samples", ir.samples()},   {"binaural", r.binaural},
              {"columnSamples", span},     {"min", lo},
              {"max", hi},                 {"envelopeBinSeconds", double(bin) / ir.sampleRate()},
              {"envelopeDb", env},         {"iacc", iacc ? iaccJson(ir) : json(nullptr)},
              {"direct", {{"visible", r.direct.visible}, {"delaySeconds", r.direct.delaySeconds},
                          {"distance", r.direct.distance}}}}
      .dump();
}

std::string irWav(const StudioIr& r) {
  const ImpulseResponse& ir = r.ir;
  const uint16_t channels = uint16_t(ir.channels());
  const uint32_t rate = uint32_t(std::lround(ir.sampleRate()));
  const uint32_t dataBytes = uint32_t(ir.samples() * channels * sizeof(float));
  std::string out;
  out.reserve(44 + dataBytes);
  out += "RIFF";
  put<uint32_t>(out, 36 + dataBytes);
  out += "WAVEfmt ";
  put<uint32_t>(out, 16);
  put<uint16_t>(out, 3);  // WAVE_FORMAT_IEEE_FLOAT
  put<uint16_t>(out, channels);
  put<uint32_t>(out, rate);
  put<uint32_t>(out, rate * channels * uint32_t(sizeof(float)));
  put<uint16_t>(out, uint16_t(channels * sizeof(float)));
  put<uint16_t>(out, 32);
  out += "data";
  put<uint32_t>(out, dataBytes);
  for (size_t n = 0; n < ir.samples(); ++n)  // interleaved frames
    for (int c = 0; c < ir.channels(); ++c) put<float>(out, ir.channel(c)[n]);
  return out;
}

}  // namespace dpc::studio
