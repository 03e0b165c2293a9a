// Baked playback: a bake's per-probe energy responses held in memory (BakedField) and the
// interpolation of a listener's response between the probes it can see (BakeInterpolator).
//
// The data come from a dpc-bake file (docs/bake-format.md; bake/bake_loader.h reads and
// validates it, the C API and dpc-demo attach it to a PropagationStage). The late part of the
// response (the stored energy without its direct sound and, with exact paths on, without every
// exact early path) is interpolated; the direct sound and its occlusion stay live
// (Simulation's DirectSound), as do the exact paths, so a door or a moving listener is heard
// at once.
//
// Interpolation (inverse-distance weighting, D. Shepard, "A two-dimensional interpolation
// function for irregularly-spaced data", ACM 1968, power 2): the `candidates` probes nearest to
// the listener are tested for line of sight to it with the scene's Tracer (any hit on the
// segment); the `maxProbes` nearest visible ones are weighted by 1/d^2, normalised to sum 1.
// A probe within kAtProbeMetres of the listener takes weight 1 alone, so the response at a
// probe is that probe's data. A probe the listener cannot see is never used (never across a
// wall); with no visible probe the caller falls back to the live simulation, counted in
// fallbacks().
// Units: metres, seconds, energy per 1 ms bin and band in 1/m^2 relative to the source power
// (EnergyResponse's scale).
#pragma once

#include <cstddef>
#include <cstdint>
#include <glm/vec3.hpp>
#include <memory>
#include <string>
#include <vector>

#include "common/bands.h"
#include "engine/energy_response.h"
#include "engine/tracer.h"

namespace dpc {

/// One bake in memory. Arrays are row-major, first index slowest, as in the bake file.
struct BakedField {
  std::string path;                ///< the file it was read from (messages)
  std::vector<glm::vec3> probes;   ///< [P] probe centres, metres
  std::vector<glm::vec3> sources;  ///< [S] baked (static) source positions, metres
  size_t bins = 0;                 ///< B: 1 ms bins per response
  double binSeconds = 1e-3;        ///< seconds per bin of `late`
  size_t directionalBinFactor = 10;  ///< energy bins per directional bin
  int shOrder = 1;                   ///< order of `sh`
  std::vector<float> late;           ///< [P][S][B][8] energy without the direct sound
  /// [P][S][D][C][8] spherical-harmonic energy of the response per directional bin
  /// (engine/sh_energy_response.h: ACN/SN3D, C = (shOrder + 1)^2, directions in the frame of a
  /// listener at yaw 0, pitch 0), without the arrivals the loader took out of `late`.
  std::vector<float> sh;
  /// The wave band (docs/bake-format.md, "The wave band"), loaded when the bake holds one and
  /// the scene plays it (wave.enabled): per source and probe the pressure IR of the wave
  /// simulation before any crossover, [S][P][waveSamples] at waveSampleRate Hz, in the
  /// ray-traced IR's units; waveReached [S][P] is 1 where the probe lies in the air the
  /// source's grid reaches (0: no wave band there, the IR holds zeros). Empty otherwise.
  std::vector<float> wave;
  std::vector<uint8_t> waveReached;
  size_t waveSamples = 0;
  int waveSampleRate = 0;
  double waveMaxFrequencyHz = 0.0;  ///< the simulation's maximum frequency, Hz
  double waveCrossoverHz = 0.0;     ///< the crossover to join it at, Hz
  bool hasWave() const { return !waveReached.empty(); }
  size_t directionalBins() const {
    return (bins + directionalBinFactor - 1) / directionalBinFactor;
  }
  size_t shChannels() const { return size_t((shOrder + 1) * (shOrder + 1)); }
  /// Bytes held by the arrays.
  size_t bytes() const;
};

/// Gives a field built in code (tests, benchmarks) the directional data of an isotropic late
/// field: in every directional bin each direction carries the same share. Allocates.
void fillUniformDirections(BakedField& field);

/// Moves the direct sound out of a probe's stored response: subtracts direct[b] from the bin of
/// `delaySeconds` (the bin the bake added it to) and clamps at 0. `energy` is [B][8]. Any
/// thread; no allocation.
void removeDirect(float* energy, size_t bins, double binSeconds, double delaySeconds,
                  const float* direct);

/// Takes one arrival (intensity per band, 1/m^2, at delaySeconds from world direction
/// `direction`) out of a probe's SH energy rows `sh` ([D][C][8], bins of dbinSeconds), from the
/// bin the bake added it to; channel 0 (the energy) is clamped at 0. Any thread; no allocation.
void removeArrivalSh(float* sh, size_t dbins, int order, double dbinSeconds, double delaySeconds,
                     const float* intensity, const glm::vec3& direction);

/// A probe used for the listener and its weight (the weights of one listener sum to 1).
struct ProbeWeight {
  size_t probe = 0;
  float weight = 0.f;
};

struct BakeInterpolation {
  int maxProbes = 4;    ///< visible probes blended, >= 1
  int candidates = 16;  ///< nearest probes tested for visibility, >= maxProbes
};

/// Per-listener interpolation over one BakedField. Construction (control thread) allocates its
/// scratch; locate/response/directional run on the propagation thread without allocating.
/// The tracer must outlive the interpolator; objects in it (doors) count as walls.
class BakeInterpolator {
 public:
  /// A listener this close to a probe (metres) takes that probe's data alone.
  static constexpr float kAtProbeMetres = 1e-3f;
  /// A world source farther than this (metres) from its baked position is not static.
  static constexpr float kStaticToleranceMetres = 0.01f;

  BakeInterpolator(std::shared_ptr<const BakedField> field, const Tracer& tracer,
                   BakeInterpolation settings = {});

  /// Chooses the probes for a listener at `listener`, metres. False (and a counted fallback)
  /// when no probe among the candidates is visible.
  bool locate(const glm::vec3& listener);
  /// The probes and weights of the last successful locate.
  const std::vector<ProbeWeight>& weights() const { return weights_; }
  /// True when world source `source` stands at its baked position (and the bake holds it).
  bool isBaked(size_t source, const glm::vec3& position) const;
  /// The interpolated late response of baked source `source` into `out` (cleared first; bins
  /// beyond the bake's stay 0). Requires a successful locate.
  void response(size_t source, EnergyResponse& out) const;
  /// The interpolated late response shared among `out`'s K directions (out's listener frame):
  /// each 1 ms bin's energy goes to direction v_k in the share max(0, f(v_k)) / sum_j
  /// max(0, f(v_j)) per band, f the directional density of the blended SH energy of its
  /// directional bin (engine/sh_energy_response.h: f(u) ~ sum_n (2n + 1) sum_m c_nm Y_nm(u),
  /// the order-N reconstruction; equal shares when every f is 0), so the K parts add up to the
  /// bin's energy. Cleared first. Allocates only when out has more directions than before.
  void directional(size_t source, DirectionalEnergyResponse& out) const;

  uint64_t located() const { return located_; }
  uint64_t fallbacks() const { return fallbacks_; }
  /// Visibility rays traced so far (the interpolation's cost in ray queries).
  uint64_t visibilityRays() const { return rays_; }
  const BakedField& field() const { return *field_; }

 private:
  const float* lateRow(size_t probe, size_t source) const;
  /// basis_[k][c] = (2n + 1) Y_c(v_k) for out's directions v_k in the bake's frame.
  void directionBasis(const DirectionalEnergyResponse& out) const;
  /// shares_[k * 8 + b]: direction k's share of band b in directional bin j (blended probes).
  void directionShares(size_t source, size_t j, size_t directions) const;

  std::shared_ptr<const BakedField> field_;
  const Tracer* tracer_;
  BakeInterpolation settings_;
  std::vector<std::pair<float, size_t>> order_;  ///< scratch: (squared distance, probe)
  std::vector<ProbeWeight> weights_;
  mutable std::vector<float> basis_, blend_, shares_;  ///< directional()'s scratch
  uint64_t located_ = 0, fallbacks_ = 0, rays_ = 0;
};

}  // namespace dpc
