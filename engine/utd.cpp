#include "engine/utd.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>

namespace dpc {

namespace {

using C = std::complex<double>;
constexpr double kPi = std::numbers::pi;

// The Kouyoumjian-Pathak transition function F(X) = 2j sqrt(X) e^{jX} int_sqrt(X)^inf e^{-jt^2} dt
// (X >= 0), to about 2e-5 absolute everywhere, in three pieces.
constexpr double kTransitionSwitch = 12.0;  // asymptotic series from here on

/// F by the power series of int_0^u e^{-jt^2} dt = sum_m (-j)^m u^{2m+1} / (m! (2m+1)),
/// subtracted from its limit (sqrt(pi) / 2) e^{-j pi / 4}: exact to rounding for X below the
/// switch (cancellation costs at most 5 of 16 digits at X = 12). Up to ~55 terms: used to
/// fill the table below.
C transitionSeries(double x) {
  // Complex products written out: std::complex's operator* takes the slow, NaN-checking path.
  const double u = std::sqrt(x);
  // sum_m power_m / (2m + 1), power_m = u (-jX)^m / m!.
  double pRe = u, pIm = 0.0, iRe = 0.0, iIm = 0.0;
  for (int m = 0; m < 80; ++m) {
    const double w = 1.0 / double(2 * m + 1);
    const double tRe = pRe * w, tIm = pIm * w;
    iRe += tRe, iIm += tIm;
    // Past the largest term (m > X) stop once a term no longer changes the sum.
    if (m > x && tRe * tRe + tIm * tIm < 1e-34 * (1.0 + iRe * iRe + iIm * iIm)) break;
    const double g = -x / double(m + 1);  // multiply by j g
    const double re = -pIm * g, im = pRe * g;
    pRe = re, pIm = im;
  }
  // limit = (sqrt(pi) / 2) e^{-j pi / 4}; F = 2j u e^{jX} (limit - integral).
  const double half = 0.5 * std::sqrt(kPi) * std::numbers::sqrt2 / 2.0;
  const double dRe = half - iRe, dIm = -half - iIm;
  const double cx = std::cos(x), sx = std::sin(x);
  const double eRe = cx * dRe - sx * dIm, eIm = cx * dIm + sx * dRe;
  return {-2.0 * u * eIm, 2.0 * u * eRe};
}

/// G(u) = F(u^2) below the switch, tabulated with its derivative G'(u) = F / u + 2ju (F - 1)
/// (from F'(X) = F (1 / 2X + j) - j; G'(0) = sqrt(pi) e^{j pi / 4}) at steps of 1/64 in u and
/// interpolated by cubic Hermite: G is smooth in u = sqrt(X), not in X. Interpolation error
/// below 5e-9 (checked against the series over X in [0, 12) at steps of 1e-4).
class TransitionTable {
 public:
  static constexpr double kStep = 1.0 / 64.0;
  TransitionTable() {
    for (size_t i = 0; i < kSize; ++i) {
      const double u = double(i) * kStep;
      g_[i] = transitionSeries(u * u);
      dg_[i] = i == 0 ? std::sqrt(kPi) * std::exp(C(0.0, kPi / 4.0))
                      : g_[i] / u + C(0.0, 2.0 * u) * (g_[i] - 1.0);
      dg_[i] *= kStep;
    }
  }
  C operator()(double x) const {
    const double v = std::sqrt(x) / kStep;
    const size_t i = std::min(size_t(v), kSize - 2);
    const double t = v - double(i), t2 = t * t, t3 = t2 * t;
    const double h00 = 2 * t3 - 3 * t2 + 1, h10 = t3 - 2 * t2 + t, h01 = -2 * t3 + 3 * t2,
                 h11 = t3 - t2;
    return {
        h00 * g_[i].real() + h10 * dg_[i].real() + h01 * g_[i + 1].real() + h11 * dg_[i + 1].real(),
        h00 * g_[i].imag() + h10 * dg_[i].imag() + h01 * g_[i + 1].imag() +
            h11 * dg_[i + 1].imag()};
  }

 private:
  static constexpr size_t kSize = size_t(3.4641016 / kStep) + 3;  // u up to sqrt(12)
  std::array<C, kSize> g_, dg_;
};

}  // namespace

// The table below the switch; from X = 12 on the asymptotic series
// F ~ sum_m (2m-1)!! / (-2jX)^m to m = 7, whose first omitted term is 2e-5 at X = 12 and falls
// as X^-8 (Kouyoumjian & Pathak 1974 give its first terms). Both pieces agree at the switch
// within that bound.
C utdTransition(double x) {
  x = std::max(x, 0.0);
  if (x < kTransitionSwitch) {
    static const TransitionTable table;
    return table(x);
  }
  // t_m = t_{m-1} (2m - 1) / (-2jX) = t_{m-1} * j (2m - 1) / (2X).
  const double h = 0.5 / x;
  double sumRe = 1.0, sumIm = 0.0, tRe = 1.0, tIm = 0.0;
  for (int m = 1; m <= 7; ++m) {
    const double g = double(2 * m - 1) * h;
    const double re = -tIm * g, im = tRe * g;
    tRe = re, tIm = im;
    sumRe += tRe, sumIm += tIm;
  }
  return {sumRe, sumIm};
}

UtdTerm utdTerm(double n, double x, int sign) {
  // At a shadow or reflection boundary cot is infinite and F zero; their product is finite
  // and continuous. Evaluate a hair off the boundary (both factors at the same angle).
  if (std::abs(std::sin((kPi + sign * x) / (2.0 * n))) < 1e-6) x += 1e-5;
  const double nRound = std::round((x + sign * kPi) / (2.0 * n * kPi));
  const double ang = (2.0 * n * kPi * nRound - x) / 2.0;
  const double arg = (kPi + sign * x) / (2.0 * n);
  return {std::cos(arg) / std::sin(arg), 2.0 * std::cos(ang) * std::cos(ang)};
}

std::array<UtdTerm, 4> utdWedgeTerms(double n, double phi, double phiSource) {
  const double dm = phi - phiSource, dp = phi + phiSource;
  return {utdTerm(n, dm, +1), utdTerm(n, dm, -1), utdTerm(n, dp, +1), utdTerm(n, dp, -1)};
}

double utdPrefactor(double n, double sinBeta0) {
  return 1.0 / (2.0 * n * std::sqrt(2.0 * kPi) * std::max(sinBeta0, 1e-9));
}

C utdScaled(const std::array<UtdTerm, 4>& terms, double prefactor, double kl) {
  double re = 0.0, im = 0.0;
  for (const UtdTerm& t : terms) {
    const C f = utdTransition(kl * t.a);
    re += t.cot * f.real(), im += t.cot * f.imag();
  }
  // -e^{-j pi/4} = (-1 + j) / sqrt 2.
  const double g = prefactor / std::numbers::sqrt2;
  return {g * (-re - im), g * (re - im)};
}

C pathPhasor(double kl) {
  const double turns = std::nearbyint(kl * (0.5 / kPi));
  const float reduced = float(std::fma(-turns, 2.0 * kPi, kl));
  float s = 0.f, c = 0.f;
  ::sincosf(reduced, &s, &c);
  return {double(c), -double(s)};
}

UtdTermSums utdTermSums(const std::array<UtdTerm, 4>& terms) {
  UtdTermSums sums;
  sums.aMin = std::numeric_limits<double>::infinity();
  for (const UtdTerm& t : terms) {
    if (t.cot == 0.0) continue;
    sums.aMin = std::min(sums.aMin, t.a);
    double w = t.cot;  // cot a^-m
    for (int m = 0; m < kUtdSeriesOrders; ++m, w /= t.a) sums.s[size_t(m)] += w;
  }
  return sums;
}

C utdScaled(const std::array<UtdTerm, 4>& terms, const UtdTermSums& sums, double prefactor,
            double kl) {
  if (!(kl * sums.aMin >= kTransitionSwitch)) return utdScaled(terms, prefactor, kl);
  // sum_m c_m j^m S_m, c_m = c_{m-1} (2m - 1) / (2 kl): j^m cycles 1, j, -1, -j.
  const double h = 0.5 / kl;
  double re = sums.s[0], im = 0.0, c = 1.0;
  for (int m = 1; m < kUtdSeriesOrders; ++m) {
    c *= double(2 * m - 1) * h;
    const double v = c * sums.s[size_t(m)];
    switch (m & 3) {
      case 1:
        im += v;
        break;
      case 2:
        re -= v;
        break;
      case 3:
        im -= v;
        break;
      default:
        re += v;
        break;
    }
  }
  // -e^{-j pi/4} = (-1 + j) / sqrt 2, as in the term-by-term sum.
  const double g = prefactor / std::numbers::sqrt2;
  return {g * (-re - im), g * (re - im)};
}

C fresnelIntegral(double u) {
  const double a = std::abs(u);
  C v;
  if (a <= 1.0) {
    // sum_m (-j)^m a^{2m+1} / (m! (2m+1)); for a <= 1 term 20 is below 1e-19.
    double pRe = a, pIm = 0.0, sRe = 0.0, sIm = 0.0;
    for (int m = 0; m < 20; ++m) {
      const double w = 1.0 / double(2 * m + 1);
      sRe += pRe * w, sIm += pIm * w;
      const double g = -a * a / double(m + 1);  // multiply by j g
      const double re = -pIm * g, im = pRe * g;
      pRe = re, pIm = im;
    }
    v = {sRe, sIm};
  } else {
    // int_a^inf e^{-jt^2} dt = F(a^2) e^{-j a^2} / (2 j a), subtracted from the limit.
    const C tail = utdTransition(a * a) * std::polar(1.0, -a * a) / C(0.0, 2.0 * a);
    v = 0.5 * std::sqrt(kPi) * std::polar(1.0, -kPi / 4.0) - tail;
  }
  return u < 0.0 ? -v : v;
}

Complex utdCoefficient(double n, double k, double phi, double phiSource, double sinBeta0,
                       double L) {
  const C d =
      utdScaled(utdWedgeTerms(n, phi, phiSource), utdPrefactor(n, sinBeta0), k * L) / std::sqrt(k);
  return {d.real(), d.imag()};
}

}  // namespace dpc
