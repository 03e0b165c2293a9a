// dpc-analyze's output formats: the parameters table, its JSON, and the band-energy CSV rows.
#pragma once

#include <array>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "analysis/room_parameters.h"
#include "common/bands.h"

namespace dpc::analyze {

/// Table cell of v with `decimals` decimals: "—" for NaN (not measurable), "+inf" / "-inf".
std::string cell(double v, int decimals);
/// s right-aligned to `width` display columns (UTF-8 aware: the em dash is one column).
std::string pad(const std::string& s, size_t width);
/// Label column and value column widths of the tables, characters.
inline constexpr size_t kLabel = 10, kColumn = 8;

/// Prints `title` and a table of T20, T30, EDT (s), C50, C80 (dB), D50 (%) and G (dB) per
/// octave band and broadband on stdout; "—" for a value that cannot be measured, "+inf" /
/// "-inf" for unbounded ratios. Main thread.
void printTable(const std::string& title, const audio::ImpulseResponseAnalysis& a);

/// Per-band parameters and the broadband ones, keyed by band centre (JSON: null for NaN,
/// "+inf" / "-inf" strings, D50 as a ratio). Allocates.
nlohmann::ordered_json analysisJson(const audio::ImpulseResponseAnalysis& a);

/// JSON text of `j`, indented by 2; bytes of a file name that are not UTF-8 become U+FFFD
/// instead of making the JSON library throw (file names on Linux are bytes, not text).
std::string dumpJson(const nlohmann::ordered_json& j);

/// The --band-energy table's comment line and header ("index" is "channel" or "source").
void printBandEnergyHeader(const std::string& file, const char* index);

/// One --band-energy table row per bin: `index,time_s,<energy per band>`, bin k starting at
/// start + k binSeconds (seconds); a band without values (above Nyquist) leaves its cells
/// empty.
void printBandEnergy(size_t index, double start, double binSeconds,
                     const std::array<std::vector<double>, kNumBands>& energy);

}  // namespace dpc::analyze
