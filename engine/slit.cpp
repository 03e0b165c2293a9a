#include "engine/slit.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>

#include "engine/utd.h"

namespace dpc {

namespace {

using C = std::complex<double>;
constexpr double kPi = std::numbers::pi;
constexpr double kEulerGamma = 0.57721566490153286;

/// A raised-cosine step from 0 at v <= lo to 1 at v >= hi, in log v.
double logStep(double v, double lo, double hi) {
  if (v <= lo) return 0.0;
  if (v >= hi) return 1.0;
  const double t = std::log(v / lo) / std::log(hi / lo);
  return 0.5 - 0.5 * std::cos(kPi * t);
}

double sinc(double x) {
  return std::abs(x) < 1e-8 ? 1.0 : std::sin(x) / x;
}

}  // namespace

C stripRadiationImpedance(double x) {
  x = std::clamp(x, 1e-9, 16.0);
  // H0^(2) = J0 - j Y0 with J0 = sum c_m t^2m, c_m = (-1)^m / (4^m m!^2), and
  // Y0 = (2 / pi) [(ln(t / 2) + gamma) J0 - sum_{m >= 1} c_m H_m t^2m] (H_m harmonic). Term by
  // term, int_0^X (X - t) t^2m dt = X^{2m+2} A_m and
  // int_0^X (X - t) t^2m ln t dt = X^{2m+2} (A_m ln X - B_m), with
  // A_m = 1 / ((2m+1)(2m+2)), B_m = (4m+3) / ((2m+1)^2 (2m+2)^2).
  const double logHalf = std::log(x / 2.0) + kEulerGamma;
  double re = 0.0, im = 0.0, c = 1.0, harmonic = 0.0, power = 1.0;
  for (int m = 0; m < 80; ++m) {
    const double m1 = 2.0 * m + 1.0, m2 = 2.0 * m + 2.0;
    const double a = 1.0 / (m1 * m2), b = (4.0 * m + 3.0) / (m1 * m1 * m2 * m2);
    const double tRe = c * power * a, tIm = c * power * (a * (logHalf - harmonic) - b);
    re += tRe;
    im += tIm;
    // Past the largest term (m > X / 2) stop once a term no longer changes the sums.
    if (m > x / 2.0 + 1.0 && std::abs(tRe) + std::abs(tIm) < 1e-17 * (std::abs(re) + std::abs(im)))
      break;
    c *= -1.0 / (4.0 * double(m + 1) * double(m + 1));
    harmonic += 1.0 / double(m + 1);
    power *= x * x;
  }
  return {re, -2.0 / kPi * im};
}

C slitTransfer(double x, double kd) {
  x = std::max(x, 1e-9);
  const C z = stripRadiationImpedance(x);
  const C denominator = 2.0 * z * std::cos(kd) + C(0.0, 1.0) * (1.0 / x + z * z * x) * std::sin(kd);
  return 2.0 / denominator;
}

double slitTransmissionCoefficient(double x, double kd) {
  x = std::max(x, 1e-9);
  return std::norm(slitTransfer(x, kd)) * stripRadiationImpedance(x).real() / x;
}

double slitWeight(double x, double aspect) {
  return (1.0 - logStep(x, kSlitFullX, kSlitEndX)) *
         logStep(aspect, kSlitMinAspect, kSlitFullAspect);
}

C slitPressure(const SlitPath& p, double k) {
  const double kt = k * p.sinBeta, x = kt * p.width;
  const C transfer = slitTransfer(x, kt * p.depth);
  const double directivity = sinc(0.5 * x * p.sinSource) * sinc(0.5 * x * p.sinListener);
  // int_a^b e^{-j alpha (z - z0)^2} dz = (F(sqrt(alpha) b) - F(sqrt(alpha) a)) / sqrt(alpha).
  const bool fitted = p.curvature > 0.0;
  const double alpha = k * (fitted ? p.curvature
                                   : 0.5 * p.sinBeta * p.sinBeta * (1.0 / p.r + 1.0 / p.s));
  const double root = std::sqrt(alpha);
  const C along = root * std::max(std::abs(p.zFrom), std::abs(p.zTo)) < 1e-6
                      ? C(p.zTo - p.zFrom, 0.0)
                      : (fresnelIntegral(root * p.zTo) - fresnelIntegral(root * p.zFrom)) / root;
  double shadow = 1.0;  // amplitude: tanh x / x, x = sqrt(2 pi N), N = 2 delta / lambda
  for (double delta : p.shadowExcess) {
    const double x = std::sqrt(2.0 * k * delta);
    if (x > 1e-6) shadow *= std::tanh(x) / x;
  }
  const C j(0.0, 1.0);
  return j / (2.0 * kPi) * transfer * directivity * shadow * along / (p.r * p.s) *
         std::polar(1.0, -k * (fitted ? p.phase : p.r + p.s));
}

namespace {

/// Z_ij of two slits (see mutualLoading): parallel and coplanar within kCoplanar, else 0.
C mutualImpedance(const CoupledSlit& a, const CoupledSlit& b) {
  constexpr double kParallel = 0.999, kCoplanar = 0.01;  // cosine; m
  if (std::abs(glm::dot(a.along, b.along)) < kParallel ||
      std::abs(glm::dot(a.normal, b.normal)) < kParallel ||
      std::abs(glm::dot(b.point - a.point, a.normal)) > kCoplanar)
    return 0.0;
  const glm::dvec3 v = b.point - a.point;
  const double d = glm::length(v - glm::dot(v, a.along) * a.along);
  const double kd = 0.5 * (a.kt + b.kt) * d;
  // Two strips narrow against d: the averaged Green's function is its value at the centres.
  if (!(kd > std::max(a.x, b.x))) return 0.0;
  // H0^(2) = J0 - j Y0 by libm's order-0 Bessel functions (POSIX j0, y0): a louvre's dozens of
  // coupled slits take thousands per frequency, where the general order's std::cyl_bessel_j and
  // std::cyl_neumann cost most of a frame.
  return 0.5 * C(::j0(kd), -::y0(kd));
}

}  // namespace

void mutualLoading(std::span<const CoupledSlit> slits, std::span<C> factors) {
  const Eigen::Index n = Eigen::Index(slits.size());
  Eigen::MatrixXcd z(n, n);
  Eigen::VectorXcd p(n);
  bool coupled = false;
  for (Eigen::Index i = 0; i < n; ++i) {
    factors[size_t(i)] = 1.0;
    p(i) = slits[size_t(i)].incident;
    z(i, i) = stripRadiationImpedance(slits[size_t(i)].x);
    for (Eigen::Index j = 0; j < i; ++j) {  // Z_ij = Z_ji: reciprocity
      z(i, j) = z(j, i) = mutualImpedance(slits[size_t(i)], slits[size_t(j)]);
      coupled = coupled || z(i, j) != 0.0;
    }
  }
  if (!coupled) return;
  // Partial pivoting: full pivoting's search takes |z| of every remaining element at each step
  // (n^3 / 3 complex magnitudes, most of a louvre's frame). A singular Z leaves q not finite.
  const Eigen::VectorXcd q = Eigen::PartialPivLU<Eigen::MatrixXcd>(z).solve(p);
  if (!q.allFinite()) return;
  for (Eigen::Index i = 0; i < n; ++i)
    if (std::abs(p(i)) > 0.0) factors[size_t(i)] = q(i) * z(i, i) / p(i);
}

}  // namespace dpc
