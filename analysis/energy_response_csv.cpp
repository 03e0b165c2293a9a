#include "analysis/energy_response_csv.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "common/input_error.h"
#include "common/input_file.h"
#include "common/output_file.h"

namespace dpc {

void writeEnergyCsv(const std::string& path, const std::vector<SourceEnergy>& sources) {
  stageEnergyCsv(path, sources).commit();
}

std::string energyCsvText(const std::vector<SourceEnergy>& sources) {
  std::ostringstream out;
  out << kEnergyCsvSignature << ": intensity per octave band relative to source power "
         "(1/m^2)\n";
  out << "source,kind,time_s";
  for (float f : kBandCentreHz) out << ",e" << int(f);
  out << "\n";
  char buf[64];
  auto values = [&](const Bands& v) {
    for (int b = 0; b < kNumBands; ++b) {
      std::snprintf(buf, sizeof buf, ",%.9g", double(v[b]));
      out << buf;
    }
    out << "\n";
  };
  size_t rows = 0;
  for (size_t s = 0; s < sources.size(); ++s) {
    const SourceEnergy& e = sources[s];
    if (e.direct.visible) {
      std::snprintf(buf, sizeof buf, "%zu,direct,%.9g", s, double(e.direct.delaySeconds));
      out << buf;
      values(e.direct.intensity);
      ++rows;
    }
    for (size_t k = 0; k < e.energy.binCount(); ++k) {
      std::snprintf(buf, sizeof buf, "%zu,bin,%.6f", s, double(k) * e.energy.binSeconds());
      out << buf;
      values(e.energy.bins()[k]);
      ++rows;
    }
  }
  out << kEnergyCsvEnd << rows << " rows\n";
  return out.str();
}

TempOutputFile stageEnergyCsv(const std::string& path, const std::vector<SourceEnergy>& sources) {
  // Like the WAV outputs: a temporary file next to `path`, renamed into place only once
  // complete, so a failure leaves neither a half-written table that could be mistaken for a
  // result nor a damaged earlier file.
  const std::string text = energyCsvText(sources);
  TempOutputFile file(path);
  file.writeAll(text.data(), text.size());
  file.finish();
  return file;
}

namespace {

/// One data row: source index, kind ("direct" or "bin"), time and band values.
struct CsvRow {
  size_t source = 0;
  std::string kind;
  double time = 0.0;
  Bands values;
};

/// Widest bin accepted, s: dpc writes 1 ms bins; beyond a second no decay can be read.
constexpr double kMaxBinSeconds = 1.0;

/// Splits and checks one data line (3 + kNumBands comma-separated fields, finite numbers).
CsvRow parseRow(const std::string& line, const std::string& path, const std::string& where) {
  std::istringstream in(line);
  std::string cell;
  std::vector<std::string> cells;
  while (std::getline(in, cell, ',')) cells.push_back(cell);
  if (cells.size() != 3 + kNumBands)
    throw InputError(path, where,
                     "expected " + std::to_string(3 + kNumBands) + " fields, found " +
                         std::to_string(cells.size()));
  double nums[1 + kNumBands];
  long source = -1;
  try {
    size_t used = 0;
    source = std::stol(cells[0], &used);
    if (used != cells[0].size()) source = -1;
    for (int i = 0; i <= kNumBands; ++i) {
      nums[i] = std::stod(cells[size_t(2 + i)], &used);
      if (used != cells[size_t(2 + i)].size() || !std::isfinite(nums[i]))
        throw std::invalid_argument("");
    }
  } catch (const std::exception&) {
    throw InputError(path, where, "a field is not a finite number");
  }
  if (source < 0 || source > 100000) throw InputError(path, where, "bad source index");
  if (cells[1] != "direct" && cells[1] != "bin")
    throw InputError(path, where, "kind must be 'direct' or 'bin', not '" + cells[1] + "'");
  CsvRow row{size_t(source), cells[1], nums[0], Bands{}};
  if (!(nums[0] >= 0.0 && nums[0] <= double(std::numeric_limits<float>::max())))
    throw InputError(path, where, "time_s must be >= 0 (and within float range)");
  for (int b = 0; b < kNumBands; ++b) {
    // Energies: a negative one is no measurement, and one beyond float is no response.
    if (!(nums[1 + b] >= 0.0 && nums[1 + b] <= double(std::numeric_limits<float>::max())))
      throw InputError(path, where, "band values must be energies >= 0 (and within float range)");
    row.values[b] = float(nums[1 + b]);
  }
  return row;
}

/// The bins' times are printed with 6 decimals (stageEnergyCsv): consecutive times may differ
/// from the bin width by up to two roundings of 5e-7 s.
constexpr double kTimeTolerance = 1.5e-6;

/// The rows of every source, gathered while reading.
struct CsvSources {
  std::vector<SourceEnergy> sources;
  std::vector<std::vector<Bands>> bins;
  std::vector<double> binSeconds;

  std::vector<double> lastTime;

  /// Adds a row (of line `where`): at most one direct row per source; bin k at time k times
  /// the bin width (the second bin's time), so that rows out of order or missing are refused
  /// instead of misplacing energy.
  void add(const CsvRow& row, const std::string& path, const std::string& where) {
    if (row.source >= sources.size()) {
      sources.resize(row.source + 1);
      bins.resize(row.source + 1);
      binSeconds.resize(row.source + 1, 0.0);
      lastTime.resize(row.source + 1, 0.0);
    }
    if (row.kind == "direct") {
      DirectSound& d = sources[row.source].direct;
      if (d.visible) throw InputError(path, where, "a second direct row for this source");
      d.visible = true;
      d.delaySeconds = float(row.time);
      d.intensity = row.values;
      return;
    }
    auto& list = bins[row.source];
    if (list.empty() && row.time > kTimeTolerance)
      throw InputError(path, where, "the first bin of a source must start at time_s 0");
    if (list.size() == 1) binSeconds[row.source] = row.time;
    if (list.size() >= 1 &&
        !(std::abs(row.time - lastTime[row.source] - binSeconds[row.source]) <= kTimeTolerance &&
          binSeconds[row.source] > kTimeTolerance &&
          binSeconds[row.source] <= kMaxBinSeconds))
      throw InputError(path, where,
                       "time_s must follow the previous bin by the bin width, at most 1 s "
                       "(bins in order, none missing)");
    lastTime[row.source] = row.time;
    list.push_back(row.values);
  }

  /// Each source's bins as an energy response (bin width from its second row; 1 ms if single).
  std::vector<SourceEnergy> finish(const std::string& path) {
    for (size_t s = 0; s < sources.size(); ++s) {
      const double bin = binSeconds[s] > 0.0 ? binSeconds[s] : 1e-3;
      if (bins[s].empty()) throw InputError(path, "source " + std::to_string(s), "has no bins");
      sources[s].energy = EnergyResponse(double(bins[s].size()) * bin, bin);
      const size_t n = std::min(bins[s].size(), sources[s].energy.binCount());
      for (size_t k = 0; k < n; ++k) sources[s].energy.bins()[k] = bins[s][k];
    }
    return std::move(sources);
  }
};

}  // namespace

namespace {

/// What the comment lines say of the file's completeness: a v2 signature requires the end line,
/// whose count must equal the data rows read before it, and no data row may follow it.
struct CsvEnding {
  bool requiresEnd = false;
  long endRows = -1;  ///< the end line's count; -1 before the end line

  void comment(const std::string& line, size_t lineNo, size_t rows, const std::string& path) {
    const std::string where = "line " + std::to_string(lineNo);
    if (lineNo == 1 && line.rfind(kEnergyCsvSignature, 0) == 0) requiresEnd = true;
    const size_t endLength = std::string(kEnergyCsvEnd).size();
    if (line.rfind(kEnergyCsvEnd, 0) != 0) return;
    if (endRows >= 0) throw InputError(path, where, "a second end line");
    size_t used = 0;
    try {
      endRows = std::stol(line.substr(endLength), &used);
    } catch (const std::exception&) {
      endRows = -2;
    }
    if (endRows < 0 || line.substr(endLength + used) != " rows")
      throw InputError(path, where, "the end line must read '# end: N rows'");
    if (size_t(endRows) != rows)
      throw InputError(path, where,
                       "the end line counts " + std::to_string(endRows) + " rows, the file has " +
                           std::to_string(rows) + " (rows lost or added)");
  }
  void row(const std::string& path, const std::string& where) const {
    if (endRows >= 0) throw InputError(path, where, "a data row after the end line");
  }
  void finish(const std::string& path, size_t rows) const {
    if (requiresEnd && endRows < 0)
      throw InputError(path, "",
                       "ends after " + std::to_string(rows) +
                           " data rows without its '# end: N rows' line: cut short");
  }
};

}  // namespace

std::vector<SourceEnergy> readEnergyCsv(const std::string& path) {
  checkInputFile(path, kMaxEnergyCsvBytes, path, "", "energy-response CSV");
  std::ifstream f(path);
  if (!f) throw InputError(path, "", "cannot open");
  CsvSources read;
  CsvEnding ending;
  std::string line;
  size_t lineNo = 0, rows = 0;
  bool header = false;
  while (std::getline(f, line)) {
    ++lineNo;
    const std::string where = "line " + std::to_string(lineNo);
    if (!line.empty() && line.back() == '\r') line.pop_back();  // a file saved with CRLF
    if (!line.empty() && line[0] == '#') ending.comment(line, lineNo, rows, path);
    if (line.empty() || line[0] == '#') continue;
    if (header) {
      ending.row(path, where);
      read.add(parseRow(line, path, where), path, where);
      ++rows;
    } else if (line.rfind("source,kind,time_s", 0) == 0) {
      header = true;
    } else {
      throw InputError(path, where, "expected the header 'source,kind,time_s,e63,...'");
    }
  }
  if (!header) throw InputError(path, "", "no header line: not a dpc energy-response CSV");
  if (read.sources.empty()) throw InputError(path, "", "no data rows after the header");
  ending.finish(path, rows);
  return read.finish(path);
}

std::array<std::vector<double>, kNumBands> withDirect(const SourceEnergy& s) {
  std::array<std::vector<double>, kNumBands> out;
  for (int b = 0; b < kNumBands; ++b) {
    auto& v = out[size_t(b)];
    v.resize(s.energy.binCount());
    for (size_t k = 0; k < v.size(); ++k) v[k] = s.energy.bins()[k][b];
    if (s.direct.visible && !v.empty()) {
      // A direct sound arriving after the last bin counts in the last bin (compared in double
      // before the conversion, which a huge delay would overflow).
      const double bin = std::max(0.0, double(s.direct.delaySeconds) / s.energy.binSeconds());
      const size_t k = bin < double(v.size() - 1) ? size_t(bin) : v.size() - 1;
      v[k] += s.direct.intensity[b];
    }
  }
  return out;
}

}  // namespace dpc
