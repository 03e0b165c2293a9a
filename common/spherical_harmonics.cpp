#include "common/spherical_harmonics.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace dpc {
namespace {

/// (n - m)! / (n + m)! for 0 <= m <= n <= kMaxAmbisonicOrder.
double factorialRatio(int n, int m) {
  double r = 1.0;
  for (int k = n - m + 1; k <= n + m; ++k) r /= double(k);
  return r;
}

/// P_n^m(x) for 0 <= m <= n <= order, without the Condon-Shortley phase, into p[n][m]
/// (standard recurrences in n from P_m^m = (2m - 1)!! (1 - x^2)^(m/2)).
using LegendreTable = double[kMaxAmbisonicOrder + 1][kMaxAmbisonicOrder + 1];
void associatedLegendre(int order, double x, LegendreTable& p) {
  const double s = std::sqrt(std::max(0.0, 1.0 - x * x));
  double pmm = 1.0;
  for (int m = 0; m <= order; ++m) {
    if (m > 0) pmm *= double(2 * m - 1) * s;
    p[m][m] = pmm;
    if (m + 1 <= order) p[m + 1][m] = x * double(2 * m + 1) * pmm;
    for (int n = m + 2; n <= order; ++n)
      p[n][m] = (double(2 * n - 1) * x * p[n - 1][m] - double(n + m - 1) * p[n - 2][m]) /
                double(n - m);
  }
}

}  // namespace

void sphericalHarmonicsSn3d(int order, const float dir[3], std::span<float> out) {
  order = std::clamp(order, 0, kMaxAmbisonicOrder);
  double x = dir[0], y = dir[1], z = dir[2];
  const double r = std::sqrt(x * x + y * y + z * z);
  if (!(r > 0.0) || !std::isfinite(r)) x = 1.0, y = 0.0, z = 0.0;
  else x /= r, y /= r, z /= r;
  const double phi = std::atan2(y, x);
  LegendreTable p;
  associatedLegendre(order, std::clamp(z, -1.0, 1.0), p);
  for (int n = 0; n <= order; ++n)
    for (int m = -n; m <= n; ++m) {
      const int a = std::abs(m);
      const double norm = std::sqrt((a == 0 ? 1.0 : 2.0) * factorialRatio(n, a));
      const double trig = m >= 0 ? std::cos(double(m) * phi) : std::sin(double(a) * phi);
      out[size_t(n * n + n + m)] = float(norm * p[n][a] * trig);
    }
}

void sphericalHarmonicsSn3dFirstOrder(const float dir[3], std::span<float> out) {
  float x = dir[0], y = dir[1], z = dir[2];
  const float r = std::sqrt(x * x + y * y + z * z);
  if (!(r > 0.f) || !std::isfinite(r)) x = 1.f, y = 0.f, z = 0.f;
  else x /= r, y /= r, z /= r;
  out[0] = 1.f;  // ACN 0 .. 3: W, Y (left), Z (up), X (forward)
  out[1] = y;
  out[2] = z;
  out[3] = x;
}

double legendre(int n, double x) {
  double p0 = 1.0, p1 = x;
  if (n == 0) return p0;
  for (int k = 2; k <= n; ++k) {
    const double p2 = (double(2 * k - 1) * x * p1 - double(k - 1) * p0) / double(k);
    p0 = p1;
    p1 = p2;
  }
  return p1;
}

double maxReRadius(int order) {
  // Newton's method on P_{N+1} from above its largest root (cos(pi / (2N + 4)) lies above it;
  // P is convex and increasing there, so the iteration descends monotonically).
  const int n = std::clamp(order, 0, kMaxAmbisonicOrder) + 1;
  double x = std::cos(std::numbers::pi / (2.0 * n + 2.0));
  for (int i = 0; i < 100; ++i) {
    const double pn = legendre(n, x), pn1 = legendre(n - 1, x);
    const double dp = double(n) * (x * pn - pn1) / (x * x - 1.0);  // P_n'(x)
    const double step = pn / dp;
    x -= step;
    if (std::abs(step) < 1e-15) break;
  }
  return x;
}

void gaussLegendreNode(int n, int k, double& x, double& w) {
  x = std::cos(std::numbers::pi * (double(k) + 0.75) / (double(n) + 0.5));
  double dp = 1.0;
  for (int i = 0; i < 100; ++i) {
    dp = double(n) * (x * legendre(n, x) - legendre(n - 1, x)) / (x * x - 1.0);
    const double step = legendre(n, x) / dp;
    x -= step;
    if (std::abs(step) < 1e-15) break;
  }
  dp = double(n) * (x * legendre(n, x) - legendre(n - 1, x)) / (x * x - 1.0);
  w = 2.0 / ((1.0 - x * x) * dp * dp);
}

void ambisonicRotation(int order, const Rotation3& r, std::span<float> out) {
  order = std::clamp(order, 0, kMaxAmbisonicOrder);
  const size_t nc = size_t(ambisonicChannels(order));
  std::array<double, ambisonicChannels(kMaxAmbisonicOrder) * ambisonicChannels(kMaxAmbisonicOrder)>
      m{};
  std::array<float, ambisonicChannels(kMaxAmbisonicOrder)> yu{}, yr{};
  const int nz = order + 1, nphi = 2 * order + 1;
  for (int k = 0; k < nz; ++k) {
    double z = 0.0, w = 2.0;
    if (order > 0) gaussLegendreNode(nz, k, z, w);
    const double s = std::sqrt(std::max(0.0, 1.0 - z * z));
    for (int j = 0; j < nphi; ++j) {
      const double phi = 2.0 * std::numbers::pi * double(j) / double(nphi);
      const float u[3] = {float(s * std::cos(phi)), float(s * std::sin(phi)), float(z)};
      const float ru[3] = {r[0] * u[0] + r[1] * u[1] + r[2] * u[2],
                           r[3] * u[0] + r[4] * u[1] + r[5] * u[2],
                           r[6] * u[0] + r[7] * u[1] + r[8] * u[2]};
      sphericalHarmonicsSn3d(order, u, yu);
      sphericalHarmonicsSn3d(order, ru, yr);
      const double weight = w * (2.0 * std::numbers::pi / double(nphi)) / (4.0 * std::numbers::pi);
      for (int n = 0; n <= order; ++n)
        for (int a = n * n; a < (n + 1) * (n + 1); ++a)
          for (int b = n * n; b < (n + 1) * (n + 1); ++b)
            m[size_t(a) * nc + size_t(b)] +=
                weight * double(2 * n + 1) * double(yr[size_t(a)]) * yu[size_t(b)];
    }
  }
  for (size_t i = 0; i < nc * nc; ++i) out[i] = float(m[i]);
}

void rotateAmbisonic(int order, std::span<const float> m, float* const* channels,
                     size_t frames) {
  order = std::clamp(order, 0, kMaxAmbisonicOrder);
  const size_t nc = size_t(ambisonicChannels(order));
  std::array<float, 2 * kMaxAmbisonicOrder + 1> in{};
  for (size_t t = 0; t < frames; ++t)
    for (int n = 1; n <= order; ++n) {  // order 0 (W) is invariant
      const size_t first = size_t(n * n), count = size_t(2 * n + 1);
      for (size_t a = 0; a < count; ++a) in[a] = channels[first + a][t];
      for (size_t a = 0; a < count; ++a) {
        float acc = 0.f;
        for (size_t b = 0; b < count; ++b) acc += m[(first + a) * nc + first + b] * in[b];
        channels[first + a][t] = acc;
      }
    }
}

void maxReWeights(int order, std::span<float> out) {
  order = std::clamp(order, 0, kMaxAmbisonicOrder);
  const double rE = maxReRadius(order);
  for (int n = 0; n <= order; ++n) out[size_t(n)] = float(legendre(n, rE));
}

}  // namespace dpc
