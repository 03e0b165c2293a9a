#include "wave/admittance.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace dpc::wave {
namespace {

/// zeta at which alpha_st of a real impedance peaks (Kuttruff, fig. 2.11): 0.951 there.
constexpr double kZetaAtPeak = 1.567;

}  // namespace

double statisticalAbsorption(double beta) {
  if (!(beta > 0.0)) return 0.0;
  const double zeta = 1.0 / beta;
  // Gauss-Legendre would do; 2,000 midpoints are exact to 1e-7 for these smooth integrands.
  constexpr int kSteps = 2000;
  const double dTheta = 0.5 * std::numbers::pi / kSteps;
  double sum = 0.0;
  for (int i = 0; i < kSteps; ++i) {
    const double theta = (i + 0.5) * dTheta;
    const double zc = zeta * std::cos(theta);
    sum += 4.0 * zc / ((zc + 1.0) * (zc + 1.0)) * std::sin(2.0 * theta);
  }
  return sum * dTheta;
}

double admittanceForAbsorption(double alpha) {
  double lo = 0.0, hi = 1.0 / kZetaAtPeak;
  if (!(alpha > 0.0)) return 0.0;
  if (alpha >= statisticalAbsorption(hi)) return hi;
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    (statisticalAbsorption(mid) < alpha ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace dpc::wave
