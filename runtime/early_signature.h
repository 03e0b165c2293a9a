// EarlySignature: what one source's own IR (its whole IR, or its early part in hybrid
// rendering: runtime/kept_irs.h) is made from, for deciding whether the IR a source played
// last still stands for its inputs now. Unlike a late bus, a source's IR is played without a
// gain of its own, so its level counts as well as its shape, and its exact arrivals are
// placed sample by sample.
//
// A signature holds:
// - the exact arrivals: the direct sound (when visible) and the exact early paths, each with
//   its delay, its octave-band intensities and, for spatial output, its direction in the
//   listener's frame; paths are matched by identity (SpecularPath::key), in key order;
// - the energy the IR holds, as a LateShape from 0 s: each band's energy in the segments
//   0-50, 50-100, 100-200 ms, ..., the diffuse response's and the exact arrivals' together
//   (what a listener hears in a window is their sum), and its total;
// - for spatial output, the listener's frame (a turned head turns every arrival).
//
// matches(made, toleranceDb) is true when nothing a listener could hear has changed:
// - the same arrivals (same paths, the direct sound visible in both or neither);
// - each arrival's delay within kDelayToleranceSeconds (a quarter sample at 48 kHz, 1.8 mm of
//   path), each band's intensity within toleranceDb (bands more than 30 dB below the arrival's
//   strongest are not compared), each direction within kDirectionToleranceDegrees (the minimum
//   audible angle, about 1 degree: Mills 1958);
// - those cells' shape (LateShape::maxDifferenceDb) and level (levelDifferenceDb) within
//   toleranceDb as they are. Not beyond a Monte Carlo margin as a late bus's shape: the margin
//   is read from the scatter between neighbouring bins, which in an early part is mostly its
//   discrete reflections, so it would let real changes through (a listener's response still
//   settling after a move kept an IR 0.9 dB off). A diffuse estimate that scatters much where
//   it carries much of the energy is then synthesised anew more often.
// The exact arrivals are deterministic, so a source and a listener that stay put give the
// same arrivals bit for bit; a moving one changes the delays by more than the tolerance within
// one frame at walking speed (1.4 m/s for 10 ms is 14 mm).
//
// Threads: any; one signature is not shared between threads while written. assign()
// allocates only beyond the reserved arrivals (reserve); no errors.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "common/bands.h"
#include "engine/energy_response.h"
#include "engine/specular_paths.h"
#include "engine/trace_request.h"
#include "runtime/late_shape.h"

namespace dpc {

class EarlySignature {
 public:
  /// A quarter of a sample at 48 kHz, seconds.
  static constexpr double kDelayToleranceSeconds = 5.2e-6;
  /// Minimum audible angle in front of a listener (Mills, JASA 30(4) 1958), degrees.
  static constexpr double kDirectionToleranceDegrees = 1.0;
  /// Bands this far below an arrival's strongest band are not compared (energy ratio, -30 dB).
  static constexpr double kBandFloor = 1e-3;

  /// Room for this many exact arrivals without allocation.
  void reserve(size_t arrivals) {
    arrivals_.reserve(arrivals);
    points_.reserve(arrivals);
  }

  /// Mono output: the early part's diffuse response (its bins from 0 s), the direct sound
  /// as synthesised (visible or not) and the exact early paths. Directions are not kept.
  void assign(const EnergyResponse& early, const DirectSound& direct,
              std::span<const SpecularPath> paths) {
    assignArrivals(direct, paths, nullptr);
    assignDiffuse(early);
  }
  /// Spatial output: the same with the directional response; directions are kept in its
  /// listener frame, and the frame itself.
  void assign(const DirectionalEnergyResponse& early, const DirectSound& direct,
              std::span<const SpecularPath> paths) {
    assignArrivals(direct, paths, &early.frame());
    assignDiffuse(early);
  }
  /// The arrivals alone (the diffuse part then unset): frame is the listener frame of spatial
  /// output, nullptr for mono. The cheap half: a moving source or listener fails on it.
  void assignArrivals(const DirectSound& direct, std::span<const SpecularPath> paths,
                      const ListenerFrame* frame);
  /// The diffuse part, after assignArrivals.
  void assignDiffuse(const EnergyResponse& early);
  void assignDiffuse(const DirectionalEnergyResponse& early);

  /// Whether an IR made from `made` stands for this signature (see the file comment):
  /// sameArrivals and sameDiffuse, both signatures with their diffuse part. toleranceDb > 0.
  bool matches(const EarlySignature& made, double toleranceDb) const {
    return sameArrivals(made, toleranceDb) && sameDiffuse(made, toleranceDb);
  }
  /// The arrivals (and for spatial output the head's frame) alone.
  bool sameArrivals(const EarlySignature& made, double toleranceDb) const;
  /// The diffuse parts alone; false unless both are assigned.
  bool sameDiffuse(const EarlySignature& made, double toleranceDb) const;

 private:
  struct Arrival {
    uint64_t key = 0;  ///< SpecularPath::key; the direct sound is arrivals_[0] when visible
    double delaySeconds = 0.0;
    Bands intensity{0.f};
    glm::vec3 direction{0.f};  ///< listener frame (spatial output), else zero
  };
  static bool sameArrival(const Arrival& a, const Arrival& b, double toleranceDb);
  /// points_ from arrivals_.
  void fillPoints();

  std::vector<Arrival> arrivals_;
  std::vector<LateShape::Point> points_;  ///< assignDiffuse's scratch: the arrivals' energies
  bool directVisible_ = false;
  bool spatial_ = false;
  bool hasDiffuse_ = false;
  ListenerFrame frame_;  ///< spatial output
  LateShape diffuse_;
};

}  // namespace dpc
