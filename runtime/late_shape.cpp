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

void LateShape::add(const EnergyResponse& r, double startSeconds) {
  for (size_t j = 0; j < r.binCount(); ++j) {
    const double t = (double(j) + 0.5) * r.binSeconds();
    if (t < startSeconds) continue;
    const int q = segmentOf(t - startSeconds);
    for (int b = 0; b < kNumBands; ++b)
      cells_[size_t(b)][size_t(q)] += std::max(0.0, double(r.bins()[j][b]));
  }
}

void LateShape::normalise() {
  total_ = 0.0;
  for (const auto& band : cells_)
    for (double c : band) total_ += c;
  if (total_ <= 0.0) return;
  for (auto& band : cells_)
    for (double& c : band) c /= total_;
}

LateShape LateShape::of(const EnergyResponse& r, double startSeconds) {
  LateShape s;
  s.add(r, startSeconds);
  s.normalise();
  return s;
}

LateShape LateShape::of(const DirectionalEnergyResponse& r, double startSeconds) {
  LateShape s;
  for (size_t d = 0; d < r.directionCount(); ++d) s.add(r.response(d), startSeconds);
  s.normalise();
  return s;
}

double LateShape::maxDifferenceDb(const LateShape& other) const {
  if ((total_ > 0.0) != (other.total_ > 0.0)) return std::numeric_limits<double>::infinity();
  double worst = 0.0;
  for (int b = 0; b < kNumBands; ++b)
    for (int q = 0; q < kSegments; ++q) {
      const double a = cells_[size_t(b)][size_t(q)], c = other.cells_[size_t(b)][size_t(q)];
      if (std::max(a, c) < kCellFloor) continue;
      if (a <= 0.0 || c <= 0.0) return std::numeric_limits<double>::infinity();
      worst = std::max(worst, std::abs(10.0 * std::log10(a / c)));
    }
  return worst;
}

}  // namespace dpc
