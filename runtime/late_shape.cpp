#include "runtime/late_shape.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace dpc {

int LateShape::segmentOf(double afterStart) {
  int q = 0;
  for (double edge = 0.05; q + 1 < kSegments && afterStart >= edge; edge *= 2.0) ++q;
  return q;
}

void LateShape::add(const EnergyResponse& r, double startSeconds, Cells& diff2) {
  bins_.fill(0);
  int lastSegment = -1;
  for (size_t j = 0; j < r.binCount(); ++j) {
    const double t = (double(j) + 0.5) * r.binSeconds();
    if (t < startSeconds) continue;
    const int q = segmentOf(t - startSeconds);
    ++bins_[size_t(q)];
    for (int b = 0; b < kNumBands; ++b) {
      const double e = std::max(0.0, double(r.bins()[j][b]));
      cells_[size_t(b)][size_t(q)] += e;
      if (q == lastSegment) {
        const double d = e - std::max(0.0, double(r.bins()[j - 1][b]));
        diff2[size_t(b)][size_t(q)] += d * d;
      }
    }
    lastSegment = q;
  }
}

void LateShape::normalise(const Cells& diff2) {
  total_ = 0.0;
  for (int b = 0; b < kNumBands; ++b)
    for (int q = 0; q < kSegments; ++q) {
      const double c = cells_[size_t(b)][size_t(q)], n = bins_[size_t(q)];
      total_ += c;
      relVar_[size_t(b)][size_t(q)] =
          n > 1.0 && c > 0.0 ? n / (n - 1.0) * 0.5 * diff2[size_t(b)][size_t(q)] / (c * c) : 0.0;
    }
  if (total_ <= 0.0) return;
  for (auto& band : cells_)
    for (double& c : band) c /= total_;
}

void LateShape::addPoints(std::span<const Point> points, double startSeconds) {
  for (const Point& p : points) {
    if (p.seconds < startSeconds) continue;
    const int q = segmentOf(p.seconds - startSeconds);
    for (int b = 0; b < kNumBands; ++b) cells_[size_t(b)][size_t(q)] += double(p.energy[b]);
  }
}

LateShape LateShape::of(const EnergyResponse& r, double startSeconds,
                        std::span<const Point> points) {
  LateShape s;
  Cells diff2{};
  s.add(r, startSeconds, diff2);
  s.addPoints(points, startSeconds);
  s.normalise(diff2);
  return s;
}

LateShape LateShape::of(const DirectionalEnergyResponse& r, double startSeconds,
                        std::span<const Point> points) {
  LateShape s;
  Cells diff2{};  // the directions' estimates are independent: their variances add
  for (size_t d = 0; d < r.directionCount(); ++d) s.add(r.response(d), startSeconds, diff2);
  s.addPoints(points, startSeconds);
  s.normalise(diff2);
  return s;
}

double LateShape::compare(const LateShape& other, double sigmas) const {
  if ((total_ > 0.0) != (other.total_ > 0.0)) return std::numeric_limits<double>::infinity();
  constexpr double kDbPerRelative = 10.0 / 2.302585092994046;  // d(10 log10 x) / dx at x = 1
  double worst = 0.0;
  for (int b = 0; b < kNumBands; ++b)
    for (int q = 0; q < kSegments; ++q) {
      const double a = cells_[size_t(b)][size_t(q)], c = other.cells_[size_t(b)][size_t(q)];
      if (std::max(a, c) < kCellFloor) continue;
      if (a <= 0.0 || c <= 0.0) return std::numeric_limits<double>::infinity();
      const double sigmaDb =
          kDbPerRelative * std::sqrt(relVar_[size_t(b)][size_t(q)] +
                                     other.relVar_[size_t(b)][size_t(q)]);
      worst = std::max(worst, std::abs(10.0 * std::log10(a / c)) - sigmas * sigmaDb);
    }
  return worst;
}

double LateShape::levelDifferenceDb(const LateShape& other) const {
  if ((total_ > 0.0) != (other.total_ > 0.0)) return std::numeric_limits<double>::infinity();
  return total_ > 0.0 ? std::abs(10.0 * std::log10(total_ / other.total_)) : 0.0;
}

double LateShape::maxDifferenceDb(const LateShape& other) const {
  return compare(other, 0.0);
}

double LateShape::maxExcessDb(const LateShape& other) const {
  return compare(other, kNoiseSigmas);
}

}  // namespace dpc
