// LateShape: what a late bus's IR depends on beyond its level, for deciding whether the IR a
// bus played last still stands for its response now (hybrid rendering, runtime/
// hybrid_synthesis.h). A bus's late IR is synthesised from its energy response; each member
// source is scaled to its own late energy by a broadband gain, so a change of level alone
// needs no new IR, only new gains. What the gains cannot follow is a change of the decay's
// shape or of the spectrum: the shape is each octave band's energy in six time segments after
// the early part's end (0-50, 50-100, 100-200, 200-400, 400-800 ms, and beyond: the ranges
// that set EDT, C80 and T30), divided by the response's total. Directional responses are
// compared on their sum over directions (the late field's directions are not compared).
//
// Threads: any; no allocation; no errors.
#pragma once

#include <array>

#include "common/bands.h"
#include "engine/energy_response.h"

namespace dpc {

class LateShape {
 public:
  static constexpr int kSegments = 6;
  /// Cells holding less than this fraction of the total are not compared (-30 dB: below
  /// what moves T30's fit or any ISO 3382-1 parameter by a just noticeable difference).
  static constexpr double kCellFloor = 1e-3;

  LateShape() = default;
  /// The shape of `r` from startSeconds on (the early part's end).
  static LateShape of(const EnergyResponse& r, double startSeconds);
  static LateShape of(const DirectionalEnergyResponse& r, double startSeconds);

  /// The largest |10 log10| ratio of this shape's cells to `other`'s over the cells where
  /// either holds at least kCellFloor, dB; +infinity when one total is 0 and the other not
  /// (0 when both are).
  double maxDifferenceDb(const LateShape& other) const;
  /// The response's energy from startSeconds on, summed over bands and segments.
  double total() const { return total_; }

 private:
  /// The segment of a time after the start, seconds.
  static int segmentOf(double afterStart);
  void add(const EnergyResponse& r, double startSeconds);
  void normalise();

  std::array<std::array<double, kSegments>, kNumBands> cells_{};
  double total_ = 0.0;
};

}  // namespace dpc
