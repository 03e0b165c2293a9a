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
// A response is a Monte Carlo estimate: with nothing moving, a cell's energy still scatters
// from frame to frame. Each cell also carries its estimate's relative variance, read from the
// response itself: a cell's n bins are taken as independent estimates around a level that
// changes little from one bin to the next, so the variance of their sum is about
// n / (n - 1) x sum (e_{k+1} - e_k)^2 / 2 (the mean squared successive difference; von Neumann
// 1941), the decay's own step between 1 ms bins (0.06 dB at T60 = 1 s) adding next to nothing.
// maxExcessDb compares two shapes beyond kNoiseSigmas of their cells' combined scatter.
// levelDifferenceDb compares the totals (a source's own IR, which has no gain to follow its
// level, compares shape and level as they are: runtime/early_signature.h).
//
// Threads: any; no allocation; no errors.
#pragma once

#include <array>
#include <span>

#include "common/bands.h"
#include "engine/energy_response.h"

namespace dpc {

class LateShape {
 public:
  static constexpr int kSegments = 6;
  /// Cells holding less than this fraction of the total are not compared (-30 dB: below
  /// what moves T30's fit or any ISO 3382-1 parameter by a just noticeable difference).
  static constexpr double kCellFloor = 1e-3;
  /// The Monte Carlo margin of maxExcessDb, in standard deviations of a cell's difference
  /// between two independent estimates: 3 leaves a cell of an unchanged response outside it
  /// with probability 0.3 % (normal errors), some 10 % of the frames for the 48 cells.
  static constexpr double kNoiseSigmas = 3.0;

  /// An exact arrival's energy at a time: what an IR holds beside its response (a source's
  /// direct sound and exact paths). Seconds; band intensities in the response's units.
  struct Point {
    double seconds = 0.0;
    Bands energy{0.f};
  };

  LateShape() = default;
  /// The shape of `r` from startSeconds on (the early part's end), with `points` added into
  /// their cells (they add no variance: they are exact).
  static LateShape of(const EnergyResponse& r, double startSeconds,
                      std::span<const Point> points = {});
  static LateShape of(const DirectionalEnergyResponse& r, double startSeconds,
                      std::span<const Point> points = {});

  /// The largest |10 log10| ratio of this shape's cells to `other`'s over the cells where
  /// either holds at least kCellFloor, dB; +infinity when one total is 0 and the other not
  /// (0 when both are).
  double maxDifferenceDb(const LateShape& other) const;
  /// The same, each cell's difference less kNoiseSigmas standard deviations of it (the two
  /// cells' relative variances added, in dB), at least 0: how far the shapes differ beyond
  /// what the estimates' Monte Carlo scatter explains. +infinity as maxDifferenceDb.
  double maxExcessDb(const LateShape& other) const;
  /// |10 log10| of the two totals' ratio, dB; +infinity when one total is 0 and the other
  /// not (0 when both are).
  double levelDifferenceDb(const LateShape& other) const;
  /// A cell's relative variance (variance of its energy over its energy squared).
  double relativeVariance(int band, int segment) const {
    return relVar_[size_t(band)][size_t(segment)];
  }
  /// The response's energy from startSeconds on, summed over bands and segments.
  double total() const { return total_; }

 private:
  using Cells = std::array<std::array<double, kSegments>, kNumBands>;
  /// The segment of a time after the start, seconds.
  static int segmentOf(double afterStart);
  /// Adds r's energies into the cells, its successive bins' squared differences into diff2.
  void add(const EnergyResponse& r, double startSeconds, Cells& diff2);
  void addPoints(std::span<const Point> points, double startSeconds);
  /// relVar_ from the cells' sums and diff2, then the cells divided by the total.
  void normalise(const Cells& diff2);
  double compare(const LateShape& other, double sigmas) const;

  Cells cells_{}, relVar_{};
  std::array<int, kSegments> bins_{};  ///< a segment's bins in one response
  double total_ = 0.0;
};

}  // namespace dpc
