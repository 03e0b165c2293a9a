// FFTW wisdom kept between runs, so that measured plans (FFTW_MEASURE: seconds per transform
// size) are measured once per machine and then made instantly: a live session's time to
// first sound no longer waits for the planner.
//
// The file: $DPC_FFTW_WISDOM when set (empty: no file, every run measures), else
// $XDG_CACHE_HOME/dpc/fftw-wisdom, else $HOME/.cache/dpc/fftw-wisdom. It is a cache: a
// missing, unreadable or foreign file is ignored (FFTW measures again) and a failed write
// loses nothing but the time the next run saves; written whole (a temporary renamed into
// place), so concurrent runs never read half a file. FFTW checks that imported wisdom fits
// the machine (its planner re-measures what does not).
//
// Call both with fftwPlannerMutex() held (common/fftw_util.h), on a control or propagation
// thread (never the audio thread: file I/O, allocation). No exceptions.
#pragma once

#include <string>

namespace dpc {

/// The wisdom file's path ("" when $DPC_FFTW_WISDOM is set and empty, or no home is known).
std::string fftwWisdomPath();

/// Imports the wisdom file into FFTW's single-precision planner, once per process.
void importFftwWisdomOnce();

/// Writes FFTW's single-precision wisdom to the file when it changed since the last import or
/// export of this process, creating its folder. Returns whether the file now holds it.
bool exportFftwWisdom();

}  // namespace dpc
