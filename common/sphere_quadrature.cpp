#include "common/sphere_quadrature.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace dpc {

namespace {

double dot(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

}  // namespace

std::array<double, 3> fibonacciPoint(int i, int n) {
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));  // golden angle, radians
  const double z = 1.0 - (2.0 * i + 1.0) / double(n);
  const double r = std::sqrt(std::max(0.0, 1.0 - z * z)), phi = golden * i;
  return {r * std::cos(phi), r * std::sin(phi), z};
}

std::vector<double> cellWeights(const std::vector<std::array<double, 3>>& directions,
                                double maxRadius, int samples) {
  std::vector<double> w(directions.size(), 0.0);
  if (directions.empty() || samples <= 0) return w;
  // Directions sorted by z: the nearest one to p lies within |z - p_z| <= its chord distance,
  // so the search walks outwards from p_z and stops beyond the best chord found.
  std::vector<size_t> order(directions.size());
  for (size_t q = 0; q < order.size(); ++q) order[q] = q;
  std::sort(order.begin(), order.end(),
            [&](size_t a, size_t b) { return directions[a][2] < directions[b][2]; });
  std::vector<double> zs(order.size());
  for (size_t i = 0; i < order.size(); ++i) zs[i] = directions[order[i]][2];
  const double minDot = std::cos(maxRadius), area = 1.0 / double(samples);
  for (int i = 0; i < samples; ++i) {
    const std::array<double, 3> p = fibonacciPoint(i, samples);
    const size_t start = size_t(std::lower_bound(zs.begin(), zs.end(), p[2]) - zs.begin());
    size_t best = order[std::min(start, order.size() - 1)];
    double bestChord2 = 2.0 - 2.0 * dot(p, directions[best]);
    const auto visit = [&](size_t k) {
      const double dz = zs[k] - p[2];
      if (dz * dz > bestChord2) return false;
      const double c2 = 2.0 - 2.0 * dot(p, directions[order[k]]);
      if (c2 < bestChord2) bestChord2 = c2, best = order[k];
      return true;
    };
    for (size_t k = start; k < order.size() && visit(k); ++k) {
    }
    for (size_t k = start; k-- > 0 && visit(k);) {
    }
    if (1.0 - 0.5 * bestChord2 >= minDot) w[best] += area;
  }
  return w;
}

double coarsestSpacing(const std::vector<std::array<double, 3>>& directions) {
  double widest = 0.0;
  for (size_t q = 0; q < directions.size(); ++q) {
    double nearest = -2.0;
    for (size_t p = 0; p < directions.size(); ++p)
      if (p != q) nearest = std::max(nearest, dot(directions[q], directions[p]));
    widest = std::max(widest, std::acos(std::clamp(nearest, -1.0, 1.0)));
  }
  return widest;
}

}  // namespace dpc
