// One probe of a bake: every static source's energy response at the probe, its direct sound,
// its ISO 3382-1 parameters and STI, each with a Monte Carlo confidence interval.
//
// Determinism: the probe's simulation is seeded with hashCombine(scene seed, probe index), and
// every ray's stream is derived from (that seed, frame, source, ray) (common/random.h), so a
// probe's result depends only on the scene, the settings and the probe's index: the same for
// any split of the probes across processes or threads.
// Estimator: plain path tracing (no reuse between frames), `frames` frames of `rays` rays per
// source; the response is the mean of the frames. The frames form `subStreams` groups of
// consecutive frames (independent random streams); each parameter's 95 % confidence half-width
// is t(G-1) s / sqrt(G), s the standard deviation of the parameter over the G groups' mean
// responses (Student's t; the groups' spread at 1/G of the rays, scaled to the full mean).
// Sources and geometry are static: sources at their position at t = 0, moving objects in their
// first keyframe's pose.
// Control thread (a rank's main thread; the tracer uses `threads` TBB threads); allocates;
// throws std::runtime_error on an Embree error.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <glm/vec3.hpp>
#include <memory>
#include <vector>

#include "scene/scene.h"

namespace dpc {
class Simulation;
}

namespace dpc::bake {

/// The parameters stored per source and band row, in this order: T20, T30, EDT (s), C50,
/// C80 (dB), D50 (ratio 0..1), G (dB re the free field at 10 m).
inline constexpr int kParameters = 7;
inline constexpr std::array<const char*, kParameters> kParameterNames = {
    "T20", "T30", "EDT", "C50", "C80", "D50", "G"};
/// Direction: the response's first-order spherical-harmonic energy per band in bins of
/// kDirectionalBinFactor energy bins (10 ms), engine/sh_energy_response.h: ACN channels 0..3
/// (W = energy, then y, z, x of the listener frame), SN3D (common/spherical_harmonics.h), in the
/// frame of a listener at yaw 0, pitch 0 (x = world +x, y = world -z, z = world +y), each
/// arrival (estimator groups, exact paths, direct sound) at its own direction. First order
/// because the late field's direction at 10 ms needs no more than its energy flow and
/// isotropy (the early arrivals a higher order would resolve are stored exactly in early/),
/// and it is the smallest: 4 floats per bin and band (25.6 kB per probe and source of 2 s;
/// order 2 would take 57.6 kB, more than the 6 axis energies of format 2's 38.4 kB).
inline constexpr int kShOrder = 1;
inline constexpr size_t kShChannels = size_t((kShOrder + 1) * (kShOrder + 1));
inline constexpr size_t kDirectionalBinFactor = 10;
/// Parameter rows per source: the 8 octave bands (63 Hz .. 8 kHz), then broadband (their sum).
inline constexpr int kParameterRows = kNumBands + 1;
/// Exact early specular paths stored per probe and source (the shortest; the scene's
/// exact_order > 0), and the floats of one: delay (s), energy per band (1/m^2), direction (3).
inline constexpr size_t kEarlyPaths = 32;
inline constexpr size_t kEarlyPathFloats = 1 + kNumBands + 3;

struct BakeSettings {
  int rays = 4096;      ///< rays per source per frame
  int frames = 8;       ///< frames per probe (a multiple of subStreams)
  int subStreams = 4;   ///< independent groups of frames for the confidence intervals (>= 2)
  int threads = 0;      ///< tracing threads per process (0: all cores)
  double irLength = 2;  ///< response length, seconds
};

/// Array sizes of one probe's result for a scene of `sources` sources.
struct ProbeShape {
  size_t sources = 0;
  size_t bins = 0;  ///< energy bins of Simulation::kEnergyBinSeconds
  size_t energyFloats() const { return sources * bins * kNumBands; }
  /// Directional bins: bins / kDirectionalBinFactor, rounded up.
  size_t directionalBins() const {
    return (bins + kDirectionalBinFactor - 1) / kDirectionalBinFactor;
  }
  size_t shFloats() const { return sources * directionalBins() * kShChannels * kNumBands; }
  size_t parameterFloats() const { return sources * kParameterRows * kParameters; }
  size_t earlyFloats() const { return sources * kEarlyPaths * kEarlyPathFloats; }
  /// All of a ProbeResult's floats, packed (pack/unpack).
  size_t packedFloats() const {
    return energyFloats() + shFloats() + sources * (1 + kNumBands + 3) +
           2 * parameterFloats() + 2 * sources + 2 * sources + earlyFloats() + energyFloats() +
           shFloats();
  }
};

ProbeShape probeShape(const SceneDesc& scene, const BakeSettings& settings);
/// Energy bins of Simulation::kEnergyBinSeconds in a response irLength seconds long.
size_t responseBins(double irLength);

struct ProbeResult {
  /// [source][bin][band]: mean energy per 1 ms bin, 1/m^2 relative to source power, the direct
  /// sound and the exact early paths included in the bins of their arrival.
  std::vector<float> energy;
  /// [source][directional bin][SH channel][band]: the spherical-harmonic energy of `energy`
  /// per 10 ms bin (kShOrder, ACN/SN3D, listener frame at yaw 0), 1/m^2; channel 0 is the
  /// energy of the bin (direct sound and exact early paths included).
  std::vector<float> sh;
  std::vector<float> directDelay;   ///< [source]: direct-sound delay, s (0 when occluded)
  std::vector<float> directEnergy;  ///< [source][band]: direct-sound intensity, 1/m^2
  /// [source][3]: unit direction from the probe toward where the direct sound comes from
  /// (world), zeros when occluded.
  std::vector<float> directDirection;
  std::vector<float> parameters;    ///< [source][row][parameter] (kParameterNames)
  std::vector<float> parametersCi;  ///< same shape: 95 % confidence half-widths
  std::vector<float> sti;           ///< [source]: STI (IEC 60268-16, noise-free), 0..1
  std::vector<float> stiCi;         ///< [source]: 95 % confidence half-width
  /// [source]: exact early paths stored (<= kEarlyPaths), and found in the last frame (more
  /// than stored when the bound was hit).
  std::vector<float> earlyCount, earlyFound;
  /// [source][path][kEarlyPathFloats]: the last frame's exact early paths, shortest first:
  /// delay (s), energy per band (1/m^2, as DirectSound), unit direction from the probe toward
  /// the last reflection point; zeros beyond earlyCount.
  std::vector<float> early;
  /// The exact early paths' part of `energy` ([source][bin][band]) and of `sh` ([source]
  /// [directional bin][SH channel][band]): every path of each frame (not only the kEarlyPaths
  /// of `early`), mean over the frames, 1/m^2. Playback takes these out of the stored response
  /// and adds the paths it finds live, so each path is heard once however many there are.
  std::vector<float> earlyEnergy, earlySh;
};

/// Bakes probes one after another with one Simulation (geometry, tracer and edge tables built
/// once), restarted for each probe with the probe's seed (Simulation::restart): each result is
/// bit-identical to a fresh Simulation's, whatever was baked before.
class ProbeBaker {
 public:
  ProbeBaker(const SceneDesc& scene, const BakeSettings& settings);
  ~ProbeBaker();
  /// Bakes probe `probe` (index in the bake) at `position`, metres.
  ProbeResult bake(size_t probe, const glm::vec3& position);
  /// Wall time of one frame (every source's rays) at `position`, metres, in seconds: a probe's
  /// cost per frame, measured to estimate a bake's time. Changes no later result (bake()
  /// restarts the simulation with the probe's seed).
  double timeFrame(const glm::vec3& position);
  /// The largest share (over sources and bands) of the emitted energy that rays still carried
  /// when the reflection order bound (propagation.max_order) ended them, in the last
  /// timeFrame() (0 before one): what a bake of these settings loses to the bound.
  double maxOrderShare() const { return maxOrderShare_; }

 private:
  const SceneDesc& scene_;
  BakeSettings settings_;
  std::unique_ptr<Simulation> sim_;
  double maxOrderShare_ = 0.0;
};

/// One probe with a baker of its own (ProbeBaker::bake).
ProbeResult bakeProbe(const SceneDesc& scene, const BakeSettings& settings, size_t probe,
                      const glm::vec3& position);

/// All arrays of a result in one buffer (the order of ProbeResult's fields), e.g. to send it
/// between processes; unpack reverses it. Allocate.
std::vector<float> pack(const ProbeResult& r);
ProbeResult unpack(const std::vector<float>& packed, const ProbeShape& shape);

}  // namespace dpc::bake
