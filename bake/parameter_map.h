// The parameter map of a bake as CSV, one row per probe, source, parameter and band:
//   probe,x_m,y_m,z_m,source,parameter,band,value,ci95
// parameter: T20, T30, EDT (s), C50, C80 (dB), D50 (ratio 0..1), G (dB), STI (0..1); band:
// the octave centre in Hz (63 .. 8000) or "broadband" (the bands' sum; STI's only row);
// ci95: the value's 95 % Monte Carlo confidence half-width (probe_bake.h). A value the
// response cannot give is "nan" (e.g. T30 of a decay recorded too short), an infinite C "inf".
// Only probes marked done are written. scripts/plot_map.py draws it. Control thread;
// allocates; written through a temporary file renamed into place (common/output_file.h);
// throws InputError naming the CSV file on a write failure.
#pragma once

#include <string>

#include "bake/bake_file.h"

namespace dpc::bake {

void writeParameterMap(const BakeFile& bake, const std::string& csvPath);

}  // namespace dpc::bake
