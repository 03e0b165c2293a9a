// dpc-demo --offline: render a scene to WAV files (and --ir-out / --er-out files).
#pragma once

#include "apps/demo/flags.h"

namespace dpc::demo {

/// Renders fl.scene offline, one WAV per listener (output_paths.h), prints one "wrote ..." line
/// per file and the run's totals on stdout, a progress bar on stderr unless --quiet.
/// Main thread (the renderer uses its own tracing threads). Returns 0; throws InputError for
/// bad input and std::exception for anything else, leaving no output file behind.
int runOffline(const Flags& fl);

}  // namespace dpc::demo
