// common/sphere_quadrature: the Fibonacci lattice and the cell weights of scattered directions,
// against areas known in closed form.
#include "common/sphere_quadrature.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>
#include <numeric>
#include <vector>

using namespace dpc;

TEST_CASE("Fibonacci lattice: unit points and equal areas on latitude bands") {
  // Equal-area lattice: the points with z in [a, b) are n (b - a) / 2 of n, to within one.
  const int n = 1000;
  int band = 0;
  for (int i = 0; i < n; ++i) {
    const auto p = fibonacciPoint(i, n);
    CHECK(std::hypot(p[0], p[1], p[2]) == Approx(1.0).margin(1e-12));
    band += p[2] >= 0.2 && p[2] < 0.7;
  }
  CHECK(std::abs(band - n * 0.5 / 2) <= 1);
}

TEST_CASE("cell weights: a uniform set gets equal weights and a hemisphere half the sphere") {
  // 500 lattice directions: every cell 1/500 of the sphere to within the sampling's error
  // (about one spacing of the 100 000-point lattice along a cell's boundary: 15 %), the whole
  // sphere covered exactly.
  std::vector<std::array<double, 3>> dirs;
  for (int i = 0; i < 500; ++i) dirs.push_back(fibonacciPoint(i, 500));
  const double spacing = coarsestSpacing(dirs);
  CHECK(spacing == Approx(std::sqrt(4 * std::numbers::pi / 500)).epsilon(0.3));
  const std::vector<double> w = cellWeights(dirs, spacing, 100000);
  CHECK(std::accumulate(w.begin(), w.end(), 0.0) == Approx(1.0).margin(1e-9));
  for (double x : w) CHECK(x * 500 == Approx(1.0).margin(0.15));
  // The upper half only: cells cut at the spacing cover the hemisphere and a band of at most
  // one spacing below the equator (area fraction sin(spacing) / 2), nothing more.
  std::vector<std::array<double, 3>> upper;
  for (const auto& d : dirs)
    if (d[2] > 0) upper.push_back(d);
  const std::vector<double> u = cellWeights(upper, spacing, 100000);
  const double covered = std::accumulate(u.begin(), u.end(), 0.0);
  CHECK(covered >= 0.5);
  CHECK(covered <= 0.5 + std::sin(spacing) / 2);
}

TEST_CASE("coarsest spacing: the six axes are 90 degrees apart") {
  const std::vector<std::array<double, 3>> axes = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                                   {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
  CHECK(coarsestSpacing(axes) == Approx(std::numbers::pi / 2).margin(1e-12));
}
