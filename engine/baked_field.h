// Baked playback: a bake's per-probe energy responses held in memory (BakedField) and the
// interpolation of a listener's response between the probes it can see (BakeInterpolator).
//
// The data come from a dpc-bake file (docs/bake-format.md; bake/bake_loader.h reads and
// validates it, the C API and dpc-demo attach it to a PropagationStage). The late part of the
// response (the stored energy without its direct sound) is interpolated; the direct sound and
// its occlusion stay live (Simulation's DirectSound), so a door or a moving listener is heard
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
  size_t directionalBinFactor = 10;     ///< energy bins per directional bin
  std::vector<glm::vec3> axes;          ///< [A] world axes of `directional` (unit)
  std::vector<float> late;              ///< [P][S][B][8] energy without the direct sound
  std::vector<float> directional;       ///< [P][S][D][A][8] energy per axis (direct included)
  size_t directionalBins() const {
    return (bins + directionalBinFactor - 1) / directionalBinFactor;
  }
  /// Bytes held by the arrays.
  size_t bytes() const;
};

/// Moves the direct sound out of a probe's stored response: subtracts direct[b] from the bin of
/// `delaySeconds` (the bin the bake added it to) and clamps at 0. `energy` is [B][8]. Any
/// thread; no allocation.
void removeDirect(float* energy, size_t bins, double binSeconds, double delaySeconds,
                  const float* direct);

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
  /// The interpolated late response shared among `out`'s directions: each 1 ms bin's energy
  /// is split among the bake's axes in the proportions of its 10 ms directional bin, each
  /// part added from that axis (out's panning and listener frame). Cleared first.
  void directional(size_t source, DirectionalEnergyResponse& out) const;

  uint64_t located() const { return located_; }
  uint64_t fallbacks() const { return fallbacks_; }
  /// Visibility rays traced so far (the interpolation's cost in ray queries).
  uint64_t visibilityRays() const { return rays_; }
  const BakedField& field() const { return *field_; }

 private:
  const float* lateRow(size_t probe, size_t source) const;
  /// Fills shares[a * 8 + b] for directional bin j of the blended probes.
  void axisShares(size_t source, size_t j, std::vector<float>& shares) const;

  std::shared_ptr<const BakedField> field_;
  const Tracer* tracer_;
  BakeInterpolation settings_;
  std::vector<std::pair<float, size_t>> order_;  ///< scratch: (squared distance, probe)
  std::vector<ProbeWeight> weights_;
  mutable std::vector<float> shares_;
  uint64_t located_ = 0, fallbacks_ = 0, rays_ = 0;
};

}  // namespace dpc
