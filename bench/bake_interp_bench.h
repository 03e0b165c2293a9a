// `dpc-bench bake-interp`: baked playback's error and cost. In a diffuse box (scattering 0.8)
// the responses at a horizontal grid of probes are interpolated (engine/baked_field.h,
// BakeInterpolator: inverse distance over the visible probes) at random points between them
// and compared with a direct simulation at each point, for several probe spacings: per-band
// energy error (dB) and C80 error (dB), direct sound live in both, and the error of the late
// response's energy vector (first-order SH energy over energy, engine/sh_energy_response.h;
// the probes' SH energy blended with the interpolation's weights). Probes and points use the
// same estimator as dpc-bake (plain path tracing, the mean of `frames` frames); the error of
// a second, independent simulation at the same points is reported as the Monte Carlo floor.
// Also the interpolation's cost per listener and frame, the live frame it replaces, and the
// memory per probe. JSON report on stdout, a line per spacing on stderr. Main thread;
// allocates.
#pragma once

#include <vector>

namespace dpc::bench {

struct BakeInterpOptions {
  std::vector<double> spacings = {0.5, 1.0, 2.0, 4.0};  ///< probe spacings, metres
  int points = 6;                                        ///< test points between probes
  int rays = 4000;                                       ///< rays per frame
  int frames = 8;                                        ///< frames averaged per response
  int threads = 0;                                       ///< tracing threads (0: all)
};

int benchBakeInterp(const BakeInterpOptions& o);

}  // namespace dpc::bench
