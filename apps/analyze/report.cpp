// dpc-analyze's tables, JSON and band-energy rows.
#include "apps/analyze/report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace dpc::analyze {
namespace {

using audio::ImpulseResponseAnalysis;
using audio::RoomParameters;

}  // namespace

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

namespace {

double strength(const RoomParameters& r) {
  return audio::strengthDb(r.energy);
}

/// One table row: the label, then a cell per band and the broadband cell.
template <class Value>
void printRow(const char* label, const ImpulseResponseAnalysis& a, Value value) {
  std::string line = label;
  line.resize(kLabel, ' ');
  for (int b = 0; b < kNumBands; ++b) line += pad(value(a.bands[size_t(b)]), kColumn);
  line += pad(value(a.broadband), kColumn + 2);
  std::printf("%s\n", line.c_str());
}

nlohmann::ordered_json toJson(double v) {
  if (std::isnan(v)) return nullptr;
  if (std::isinf(v)) return v > 0 ? "+inf" : "-inf";
  return v;
}

nlohmann::ordered_json toJson(const RoomParameters& r) {
  return {{"t20", toJson(r.t20)},
          {"t30", toJson(r.t30)},
          {"edt", toJson(r.edt)},
          {"c50", toJson(r.c50)},
          {"c80", toJson(r.c80)},
          {"d50", toJson(r.d50)},
          {"g", toJson(strength(r))},
          {"inr", toJson(r.inrDb)},
          {"truncation", toJson(r.truncationSeconds)}};
}

bool anyNoiseFloor(const ImpulseResponseAnalysis& a) {
  if (!std::isnan(a.broadband.inrDb)) return true;
  for (const RoomParameters& r : a.bands)
    if (!std::isnan(r.inrDb)) return true;
  return false;
}

}  // namespace

void printTable(const std::string& title, const ImpulseResponseAnalysis& a) {
  std::printf("%s\n", title.c_str());
  std::string header = std::string(kLabel, ' ');
  for (int b = 0; b < kNumBands; ++b)
    header += pad(std::to_string(int(kBandCentreHz[size_t(b)])), kColumn);
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
  for (const Row& row : rows)
    printRow(row.label, a,
             [&](const RoomParameters& r) { return cell(r.*row.field * row.scale, row.decimals); });
  printRow("G (dB)", a, [](const RoomParameters& r) { return cell(strength(r), 1); });
  if (!anyNoiseFloor(a)) return;
  // A measured IR's background noise (analysis/noise_floor.h): where it was found, the
  // parameters above are noise-compensated (ISO 3382-1:2009 5.3.3).
  printRow("INR (dB)", a, [](const RoomParameters& r) { return cell(r.inrDb, 1); });
  printRow("cut at (s)", a, [](const RoomParameters& r) { return cell(r.truncationSeconds, 2); });
}

nlohmann::ordered_json analysisJson(const ImpulseResponseAnalysis& a) {
  nlohmann::ordered_json bands = nlohmann::ordered_json::array();
  for (int b = 0; b < kNumBands; ++b) {
    nlohmann::ordered_json entry = {{"centreHz", kBandCentreHz[size_t(b)]}};
    entry.update(toJson(a.bands[size_t(b)]));
    bands.push_back(entry);
  }
  return {{"bands", bands}, {"broadband", toJson(a.broadband)}};
}

std::string dumpJson(const nlohmann::ordered_json& j) {
  return j.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace);
}

void printBandEnergyHeader(const std::string& file, const char* index) {
  std::printf("# dpc-analyze --band-energy: %s\n%s,time_s", file.c_str(), index);
  for (int b = 0; b < kNumBands; ++b) std::printf(",%g", kBandCentreHz[size_t(b)]);
  std::printf("\n");
}

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

}  // namespace dpc::analyze
