// Energy-response export: the band energy response of each source as CSV, and its reader.
//
// Format (one file, all sources; docs/validation.md "Energy-response export"):
//   # dpc energy response v2: intensity per octave band relative to source power (1/m^2)
//   source,kind,time_s,e63,e125,e250,e500,e1000,e2000,e4000,e8000
//   0,direct,0.0087463,<8 values>     exact arrival of the analytic direct sound (omitted when
//                                      occluded), band intensity 1/(4 pi r^2) x air absorption
//   0,bin,0.000,<8 values>            every bin of the energy response: time_s is the bin's
//   0,bin,0.001,...                   start, values its energy over [t, t + bin) (1 ms bins)
//   # end: 2004 rows                   the last line: the number of data rows above it
// Sources are numbered from 0 in scene order. Lines starting with '#' are comments. A file that
// says v2 in its first line must end with the end line and its count (a file cut short at a
// line boundary otherwise reads as a shorter response); v1 (dpc before the end line) and files
// without the signature are read without that check.
//
// Any thread except the audio thread; allocates. writeEnergyCsv writes a temporary file in the
// destination folder and renames it to the path only when complete (common/output_file.h): on
// failure it throws InputError naming the path, removes the temporary and leaves any existing
// file untouched. readEnergyCsv throws InputError naming the file and the line.
#pragma once

#include <string>
#include <vector>

#include "common/output_file.h"
#include "engine/energy_response.h"
#include "engine/propagation.h"

namespace dpc {

/// The first line's start, naming the format and its version.
inline constexpr const char* kEnergyCsvSignature = "# dpc energy response v2";
/// The last line's start, followed by the number of data rows and " rows".
inline constexpr const char* kEnergyCsvEnd = "# end: ";

/// One source's exported response: bins of binSeconds, and the direct sound (if visible).
struct SourceEnergy {
  EnergyResponse energy;
  DirectSound direct;  ///< visible, delaySeconds and intensity are what the file holds
};

void writeEnergyCsv(const std::string& path, const std::vector<SourceEnergy>& sources);
/// As writeEnergyCsv, but the complete temporary is returned instead of renamed to `path`,
/// for a run that renames all its outputs together (OutputSet, common/output_file.h).
TempOutputFile stageEnergyCsv(const std::string& path, const std::vector<SourceEnergy>& sources);
/// The file's text (what writeEnergyCsv writes), e.g. to serve it (dpc studio).
std::string energyCsvText(const std::vector<SourceEnergy>& sources);
std::vector<SourceEnergy> readEnergyCsv(const std::string& path);

/// The response with the direct sound added to the bin holding its arrival (for analysis),
/// as doubles per band: out[b][k].
std::array<std::vector<double>, kNumBands> withDirect(const SourceEnergy& s);

}  // namespace dpc
