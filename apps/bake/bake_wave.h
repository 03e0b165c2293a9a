// The wave band of a bake (docs/bake.md, "The wave band"): with the scene's wave.enabled, one
// wave simulation per source (wave/wave_band.h) with every probe as a receiver, committed to
// the bake file source by source (bake/bake_file.h, BakeFile::commitWave). Probes that lie in
// no air the source's grid reaches are reported on stderr (one line per source, with the count
// and the first such probe), stored with wave/reached 0 and zeros: they carry no wave band.
// A resumed bake simulates again the sources the file does not hold (a source interrupted
// mid-simulation starts over; the result is the same bytes).
// Rank 0's main thread, before its probes; allocates (one source's grid and its probes' IRs);
// errors as InputError (wave/wave_band.h) or a refused write (bake/bake_file.h).
#pragma once

#include <cstddef>
#include <vector>

#include "apps/bake/bake_plan.h"
#include "apps/bake/estimate.h"
#include "apps/bake/watchdog.h"
#include "bake/bake_file.h"

namespace dpc::bake {

/// The wave band's simulations for `scene` (wave.enabled) with IRs irLength seconds long, from
/// the grid's layout alone (no grid is built). Throws InputError(scene file,
/// "wave.max_frequency") for a grid beyond kMaxWaveNodes, as the simulation would.
WaveEstimate estimateWave(const SceneDesc& scene, double irLength);

/// The largest probe spacing the blend of the probes' wave bands was measured at, as a
/// fraction of the wavelength at the crossover, rounded up (1 m at 125 Hz: 0.36; 1.4 dB mean
/// and 4.1 dB largest error halfway between four probes: docs/wave.md, "In the bake").
/// Beyond it the blend is unmeasured, and its error grows with the phase between the probes.
inline constexpr double kWaveBlendMeasuredSpacing = 0.37;

/// One warning line on stderr when a fresh bake's probe grid spacing (metres) exceeds
/// kWaveBlendMeasuredSpacing of the wavelength at the scene's wave crossover: the wave band
/// blended between probes that far apart loses level. Nothing without the wave band.
void warnWaveProbeSpacing(const SceneDesc& scene, double spacingM);

/// What the wave band of a run cost and found.
struct WaveBakeStats {
  size_t sources = 0;    ///< simulated and stored in this run
  size_t unreached = 0;  ///< (source, probe) pairs outside the source's air, over those sources
  double seconds = 0.0;  ///< wall time, grids built, simulated and stored
};

/// Simulates and commits the wave band of every source in plan.waveTodo, with progress and an
/// ETA on stderr unless `quiet`; each commit under the watchdog's lock when there is one.
/// False when a stop signal came (the source being simulated is not stored).
bool bakeWaveBands(const Plan& plan, BakeFile& file, bool quiet, Watchdog* watchdog,
                   WaveBakeStats& stats);

}  // namespace dpc::bake
