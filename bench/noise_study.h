// Noise study: how far an estimator's per-frame energy response is from a converged
// reference, how much it flickers from frame to frame, and its bias (docs/design.md, "How we know
// it is right"; Schissler thesis 3.2.2 claims the DPC needs far fewer rays for equal noise).
//
// All metrics use the band energy response in 10 ms bins (rebinned from Simulation's 1 ms),
// all 8 bands, every bin of the IR length, with the L2 norm over (band, bin):
//   error_f   = ||E_f - R|| / ||R||               (relative RMS error of frame f)
//   flicker_f = ||E_f - E_{f-1}|| / ||R||         (frame-to-frame change)
//   bias      = ||mean_f E_f - R|| / ||R||        (systematic part; includes the residual
//                                                  noise of the mean, ~ error / sqrt(frames))
//   energyBias = (sum mean_f E_f - sum R) / sum R (signed, total energy)
// The reference is plain path tracing averaged over many frames (independent seeds) at the
// same listener position: an unbiased estimate whose own relative error is reported.
// Propagation (or test) thread; allocates; no errors beyond Simulation's.
#pragma once

#include <functional>
#include <vector>

#include "engine/energy_response.h"
#include "scene/scene.h"

namespace dpc {

struct NoiseMetrics {
  double meanError = 0.0;    ///< mean of error_f over the measured frames
  double meanFlicker = 0.0;  ///< mean of flicker_f over the measured frames
  double bias = 0.0;
  double energyBias = 0.0;
  std::vector<double> errorPerFrame;  ///< error_f for every frame, warm-up included
  /// Per delay range (measureNoise's `ranges`): mean over measured frames of
  /// ||E_f - R|| / ||R|| restricted to the 10 ms bins whose start lies in the range.
  std::vector<double> errorByRange;
  /// Total energy of each frame's energy response (every bin and band), warm-up included.
  std::vector<double> energyPerFrame;
  int frames = 0;  ///< measured frames (after warm-up)
};

/// Converged reference: the mean energy response of `frames` plain path-tracing frames with
/// settings.raysPerFrame rays each, listener static at `listener`. Also returns the
/// reference's own relative error estimate (standard error of the mean) in *selfError, and,
/// if `ranges` and `selfErrorByRange` are given, the same restricted to each delay range
/// [first, second) seconds (as measureNoise's errorByRange is).
EnergyResponse referenceResponse(const SceneDesc& scene, PropagationSettings settings,
                                 const glm::vec3& listener, int frames, double* selfError,
                                 size_t source = 0,
                                 const std::vector<std::pair<double, double>>* ranges = nullptr,
                                 std::vector<double>* selfErrorByRange = nullptr);

/// Runs `warmup + frames` frames of the estimator in `settings` with the listener at
/// listenerAt(frame) and compares each frame with referenceAt(frame) (10 ms bins). sourceAt
/// (optional): source `source` at sourceAt(frame) instead of its scene position (a walking
/// source; the reference must then be computed at that position).
NoiseMetrics measureNoise(const SceneDesc& scene, const PropagationSettings& settings, int warmup,
                          int frames, const std::function<glm::vec3(int)>& listenerAt,
                          const std::function<const EnergyResponse&(int)>& referenceAt,
                          size_t source = 0,
                          const std::function<glm::vec3(int)>& sourceAt = nullptr,
                          const std::vector<std::pair<double, double>>& ranges = {});

/// Delay range [t0, t1) seconds in which reflection orders [d0, d1] arrive on average: the mean
/// reflection rate of a room is c S / (4 V) (Kuttruff, Room Acoustics, section 5.1), so order d
/// arrives around d 4 V / (c S) after the direct sound; the range starts half an order early.
std::pair<double, double> delayRangeOfOrders(int d0, int d1, double volume, double surfaceArea,
                                             double c, double directDelay);

/// What the diffuse path cache's total energy must be at each frame, given the totals of plain
/// path tracing on the same rays (perFrame[f], frames 0..): for the window weighting the mean
/// of the last min(f + 1, W) frames, W = round(tau * frameRate); for the EMA the exponential
/// average with a = 1 - exp(-1 / (tau * frameRate)) started from zero and divided by
/// 1 - (1 - a)^(f + 1), as the cache reads it out. An unbiased estimator matches it up to
/// float rounding. The seed weighting has no such expectation (it is biased); it throws
/// std::invalid_argument.
std::vector<double> cacheAveraged(const std::vector<double>& perFrame, DpcWeighting weighting,
                                  double tau, double frameRate);

/// 10 ms bins used by the study.
inline constexpr double kNoiseBinSeconds = 0.010;

/// A Simulation energy response (1 ms bins) rebinned to the study's 10 ms bins.
EnergyResponse noiseBins(const EnergyResponse& e);
/// error = ||e - ref|| / ||ref|| over every 10 ms bin and band (e and ref from noiseBins).
double relativeError(const EnergyResponse& e, const EnergyResponse& ref);

}  // namespace dpc
