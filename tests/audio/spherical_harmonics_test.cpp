// Tests for common/spherical_harmonics: ACN/SN3D real spherical harmonics against the
// published closed forms, and max-rE energy vectors of a decoded plane wave.
#include "common/spherical_harmonics.h"

#include <array>
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>
#include <vector>

using namespace dpc;

namespace {

using Channels = std::array<float, ambisonicChannels(kMaxAmbisonicOrder)>;

Channels sh(int order, double x, double y, double z) {
  const float d[3] = {float(x), float(y), float(z)};
  Channels out{};
  sphericalHarmonicsSn3d(order, d, out);
  return out;
}

/// The SN3D closed forms of orders 0..3 in ACN order (W Y Z X V T R S U Q O M K L N P) as
/// tabulated for AmbiX (Nachbar, Zotter, Deleflie and Sontacchi, "ambiX - a suggested
/// Ambisonics format", 2011): azimuth phi, elevation theta. Written out here, independently of
/// the recurrence the library uses.
std::array<double, 16> publishedTable(double phi, double theta) {
  const double s = std::sin(theta), c = std::cos(theta);
  const double r3 = std::sqrt(3.0);
  return {1.0,
          std::sin(phi) * c,
          s,
          std::cos(phi) * c,
          r3 / 2 * c * c * std::sin(2 * phi),
          r3 / 2 * std::sin(2 * theta) * std::sin(phi),
          (3 * s * s - 1) / 2,
          r3 / 2 * std::sin(2 * theta) * std::cos(phi),
          r3 / 2 * c * c * std::cos(2 * phi),
          std::sqrt(5.0 / 8) * c * c * c * std::sin(3 * phi),
          std::sqrt(15.0) / 2 * s * c * c * std::sin(2 * phi),
          std::sqrt(3.0 / 8) * c * (5 * s * s - 1) * std::sin(phi),
          s * (5 * s * s - 3) / 2,
          std::sqrt(3.0 / 8) * c * (5 * s * s - 1) * std::cos(phi),
          std::sqrt(15.0) / 2 * s * c * c * std::cos(2 * phi),
          std::sqrt(5.0 / 8) * c * c * c * std::cos(3 * phi)};
}

/// Gauss-Legendre nodes and weights on [-1, 1] (Newton on P_n from the Chebyshev guesses).
void gaussLegendre(int n, std::vector<double>& x, std::vector<double>& w) {
  x.resize(size_t(n));
  w.resize(size_t(n));
  for (int i = 0; i < n; ++i) {
    double z = std::cos(std::numbers::pi * (i + 0.75) / (n + 0.5)), dp = 1;
    for (int it = 0; it < 100; ++it) {
      dp = n * (z * legendre(n, z) - legendre(n - 1, z)) / (z * z - 1);
      z -= legendre(n, z) / dp;
    }
    x[size_t(i)] = z;
    w[size_t(i)] = 2 / ((1 - z * z) * dp * dp);
  }
}

struct Decoded {
  double energy = 0;
  std::array<double, 3> rE{};
};

/// A plane wave from `src` encoded at `order` with max-rE weights, decoded by the sampling
/// decoder g(u) = sum_n (2n + 1) a_n sum_m Y_nm(u) Y_nm(src) on a Gauss-Legendre x
/// equiangular quadrature exact to degree 2N + 3 (the energy vector's integrand has degree
/// 2N + 1): energy = integral of g^2 / 4 pi, rE = integral of g^2 u / integral of g^2.
Decoded decodePlaneWave(int order, const std::array<double, 3>& src) {
  std::array<float, kMaxAmbisonicOrder + 1> a{};
  maxReWeights(order, a);
  const Channels ys = sh(order, src[0], src[1], src[2]);
  std::vector<double> zs, ws;
  gaussLegendre(order + 2, zs, ws);
  const int nphi = 2 * order + 4;
  Decoded d;
  std::array<double, 3> sum{};
  for (size_t i = 0; i < zs.size(); ++i)
    for (int k = 0; k < nphi; ++k) {
      const double phi = 2 * std::numbers::pi * k / nphi, c = std::sqrt(1 - zs[i] * zs[i]);
      const std::array<double, 3> u{c * std::cos(phi), c * std::sin(phi), zs[i]};
      const Channels yu = sh(order, u[0], u[1], u[2]);
      double g = 0;
      for (int n = 0; n <= order; ++n)
        for (int ch = n * n; ch < (n + 1) * (n + 1); ++ch)
          g += (2 * n + 1) * a[size_t(n)] * double(yu[size_t(ch)]) * ys[size_t(ch)];
      const double e = ws[i] * (2 * std::numbers::pi / nphi) * g * g;
      d.energy += e;
      for (int j = 0; j < 3; ++j) sum[size_t(j)] += e * u[size_t(j)];
    }
  for (int j = 0; j < 3; ++j) d.rE[size_t(j)] = sum[size_t(j)] / d.energy;
  d.energy /= 4 * std::numbers::pi;
  return d;
}

/// Largest abscissa of the n-point Gauss-Legendre rule, n = 2..8 (Abramowitz & Stegun,
/// Handbook of Mathematical Functions, Table 25.4): max-rE's |rE| at orders 1..7 (Zotter &
/// Frank 2019, ch. 4: r_E = the largest root of P_{N+1}).
constexpr std::array<double, 7> kMaxReTable = {0.577350269, 0.774596669, 0.861136312, 0.906179846,
                                               0.932469514, 0.949107912, 0.960289856};

const std::array<std::array<double, 3>, 8> kSources = {{{1, 0, 0},
                                                        {0, 1, 0},
                                                        {0, 0, 1},
                                                        {-0.3, 0.5, 0.81},
                                                        {0.6, -0.7, -0.38},
                                                        {-0.9, -0.2, 0.39},
                                                        {0.1, 0.2, -0.97},
                                                        {-0.5, 0.5, -0.7}}};

}  // namespace

TEST_CASE("SN3D/ACN on the +-x, +-y, +-z axes equal the published table") {
  const double pi = std::numbers::pi;
  struct Axis {
    std::array<double, 3> v;
    double phi, theta;
  };
  const Axis axes[] = {{{1, 0, 0}, 0, 0},       {{-1, 0, 0}, pi, 0},       {{0, 1, 0}, pi / 2, 0},
                       {{0, -1, 0}, -pi / 2, 0}, {{0, 0, 1}, 0, pi / 2},   {{0, 0, -1}, 0, -pi / 2}};
  for (const Axis& a : axes) {
    const Channels got = sh(3, a.v[0], a.v[1], a.v[2]);
    const auto want = publishedTable(a.phi, a.theta);
    for (size_t c = 0; c < 16; ++c) {
      INFO("axis " << a.v[0] << "," << a.v[1] << "," << a.v[2] << " ACN " << c);
      CHECK(got[c] == Approx(want[c]).margin(1e-6));  // float rounding of values <= 1
    }
  }
  // A few values written out: +x has U = sqrt(3)/2, L = -sqrt(3/8), P = sqrt(5/8).
  const Channels x = sh(3, 1, 0, 0);
  CHECK(x[0] == 1.f);
  CHECK(x[3] == Approx(1.0).margin(1e-7));
  CHECK(x[6] == Approx(-0.5).margin(1e-7));
  CHECK(x[8] == Approx(0.8660254).margin(1e-6));
  CHECK(x[13] == Approx(-0.6123724).margin(1e-6));
  CHECK(x[15] == Approx(0.7905694).margin(1e-6));
  const Channels z = sh(3, 0, 0, -1);  // nadir: Z = -1, R = 1, K = -1
  CHECK(z[2] == Approx(-1.0).margin(1e-7));
  CHECK(z[6] == Approx(1.0).margin(1e-7));
  CHECK(z[12] == Approx(-1.0).margin(1e-7));
}

TEST_CASE("SN3D/ACN match the table off the axes and obey the addition theorem up to order 7") {
  for (const auto& s : kSources) {
    const double r = std::hypot(s[0], s[1], s[2]);
    const double phi = std::atan2(s[1], s[0]), theta = std::asin(s[2] / r);
    const Channels got = sh(3, s[0], s[1], s[2]);
    const auto want = publishedTable(phi, theta);
    for (size_t c = 0; c < 16; ++c) CHECK(got[c] == Approx(want[c]).margin(1e-6));
    // sum_m Y_nm(u) Y_nm(v) = P_n(u . v) in SN3D (Zotter & Frank 2019, ch. 4), for all orders.
    for (const auto& t : kSources) {
      const double rt = std::hypot(t[0], t[1], t[2]);
      const double cosg = (s[0] * t[0] + s[1] * t[1] + s[2] * t[2]) / (r * rt);
      const Channels a = sh(kMaxAmbisonicOrder, s[0], s[1], s[2]);
      const Channels b = sh(kMaxAmbisonicOrder, t[0], t[1], t[2]);
      for (int n = 0; n <= kMaxAmbisonicOrder; ++n) {
        double dot = 0;
        for (int c = n * n; c < (n + 1) * (n + 1); ++c) dot += double(a[size_t(c)]) * b[size_t(c)];
        CHECK(dot == Approx(legendre(n, cosg)).margin(1e-5));  // 2n + 1 float products
      }
    }
  }
}

TEST_CASE("SN3D/ACN first order without trigonometry equals the general evaluation") {
  for (const auto& s : kSources) {
    const Channels all = sh(1, s[0], s[1], s[2]);
    const float dir[3] = {float(s[0]), float(s[1]), float(s[2])};
    std::array<float, 4> fast{};
    sphericalHarmonicsSn3dFirstOrder(dir, fast);
    for (size_t c = 0; c < 4; ++c) CHECK(fast[c] == Approx(all[c]).margin(1e-6));  // rounding
  }
  const float none[3] = {0.f, 0.f, 0.f};
  std::array<float, 4> ahead{};
  sphericalHarmonicsSn3dFirstOrder(none, ahead);
  CHECK(ahead == std::array<float, 4>{1.f, 0.f, 0.f, 1.f});
}

TEST_CASE("max-rE radius equals the tabulated largest Legendre root") {
  for (int n = 1; n <= kMaxAmbisonicOrder; ++n)
    CHECK(maxReRadius(n) == Approx(kMaxReTable[size_t(n - 1)]).margin(1e-9));  // table: 9 digits
  std::array<float, kMaxAmbisonicOrder + 1> a{};
  maxReWeights(1, a);  // a_1 = P_1(1/sqrt 3)
  CHECK(a[0] == 1.f);
  CHECK(a[1] == Approx(0.5773503).margin(1e-6));
}

TEST_CASE("a decoded plane wave's energy vector points at the source with max-rE length") {
  for (int order : {1, 3, 5}) {
    double e0 = -1, worstDeg = 0, worstLen = 0;
    for (const auto& s : kSources) {
      const double r = std::hypot(s[0], s[1], s[2]);
      const Decoded d = decodePlaneWave(order, s);
      const double len = std::hypot(d.rE[0], d.rE[1], d.rE[2]);
      const double cosErr = (d.rE[0] * s[0] + d.rE[1] * s[1] + d.rE[2] * s[2]) / (len * r);
      const double errDeg = std::acos(std::min(1.0, cosErr)) * 180 / std::numbers::pi;
      INFO("order " << order << " source " << s[0] << "," << s[1] << "," << s[2]);
      CHECK(errDeg < 2.0);  // the bound; the quadrature is exact, so it is ~0
      // |rE| = the order's tabulated max-rE value; 1e-5: float encoding of the harmonics.
      CHECK(len == Approx(kMaxReTable[size_t(order - 1)]).margin(1e-5));
      // Energy is the same for every direction (an isotropic encoder and decoder): 1e-5
      // relative, float rounding of (N+1)^2 products.
      if (e0 < 0) e0 = d.energy;
      CHECK(d.energy == Approx(e0).epsilon(1e-5));
      worstDeg = std::max(worstDeg, errDeg);
      worstLen = std::max(worstLen, std::abs(len - kMaxReTable[size_t(order - 1)]));
    }
    WARN("order " << order << ": largest rE direction error " << worstDeg
                  << " deg, largest |rE| - max-rE " << worstLen);
  }
}

namespace {

/// A rotation matrix (row-major) from axis-angle, Rodrigues' formula.
Rotation3 rotation(double ax, double ay, double az, double angle) {
  const double n = std::hypot(ax, ay, az);
  ax /= n, ay /= n, az /= n;
  const double c = std::cos(angle), s = std::sin(angle), t = 1 - c;
  return {float(t * ax * ax + c),      float(t * ax * ay - s * az), float(t * ax * az + s * ay),
          float(t * ax * ay + s * az), float(t * ay * ay + c),      float(t * ay * az - s * ax),
          float(t * ax * az - s * ay), float(t * ay * az + s * ax), float(t * az * az + c)};
}

std::array<double, 3> apply(const Rotation3& r, const std::array<double, 3>& v) {
  return {r[0] * v[0] + r[1] * v[1] + r[2] * v[2], r[3] * v[0] + r[4] * v[1] + r[5] * v[2],
          r[6] * v[0] + r[7] * v[1] + r[8] * v[2]};
}

const Rotation3 kRotations[] = {rotation(0, 0, 1, 0.7), rotation(1, 0, 0, -1.2),
                                rotation(0.3, -0.5, 0.8, 2.5), rotation(-0.9, 0.1, 0.4, 3.0)};

}  // namespace

TEST_CASE("Ambisonic rotation: M(R) Y(s) = Y(R s), orthogonal blocks, composition") {
  using Matrix = std::array<float, 64 * 64>;
  for (int order : {1, 3, 7}) {
    const size_t nc = size_t(ambisonicChannels(order));
    for (const Rotation3& r : kRotations) {
      Matrix m{};
      ambisonicRotation(order, r, m);
      for (const auto& s : kSources) {
        const Channels ys = sh(order, s[0], s[1], s[2]);
        const auto rs = apply(r, s);
        const Channels want = sh(order, rs[0], rs[1], rs[2]);
        for (size_t a = 0; a < nc; ++a) {
          double got = 0;
          for (size_t b = 0; b < nc; ++b) got += double(m[a * nc + b]) * ys[b];
          INFO("order " << order << " ACN " << a);
          CHECK(got == Approx(want[a]).margin(2e-5));  // float harmonics, sums of <= 15 terms
        }
      }
      // Each order's block is orthogonal: M M^T = I.
      for (size_t a = 0; a < nc; ++a)
        for (size_t b = 0; b < nc; ++b) {
          double dot = 0;
          for (size_t k = 0; k < nc; ++k) dot += double(m[a * nc + k]) * m[b * nc + k];
          CHECK(dot == Approx(a == b ? 1.0 : 0.0).margin(2e-5));
        }
    }
    // Composition: M(R1) M(R2) = M(R1 R2).
    Rotation3 r12{};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        for (int k = 0; k < 3; ++k)
          r12[size_t(3 * i + j)] += kRotations[0][size_t(3 * i + k)] * kRotations[2][size_t(3 * k + j)];
    Matrix m1{}, m2{}, m12{};
    ambisonicRotation(order, kRotations[0], m1);
    ambisonicRotation(order, kRotations[2], m2);
    ambisonicRotation(order, r12, m12);
    for (size_t a = 0; a < nc; ++a)
      for (size_t b = 0; b < nc; ++b) {
        double p = 0;
        for (size_t k = 0; k < nc; ++k) p += double(m1[a * nc + k]) * m2[k * nc + b];
        CHECK(p == Approx(m12[a * nc + b]).margin(3e-5));
      }
  }
}

TEST_CASE("Ambisonic rotation of a signal block equals encoding from the rotated direction") {
  const int order = 3;
  const size_t frames = 64;
  const auto s = kSources[4];
  const Channels ys = sh(order, s[0], s[1], s[2]);
  std::vector<std::vector<float>> block(16, std::vector<float>(frames));
  std::vector<float*> ptrs;
  for (size_t c = 0; c < 16; ++c) {
    for (size_t t = 0; t < frames; ++t) block[c][t] = ys[c] * std::sin(0.3f * float(t) + 1.f);
    ptrs.push_back(block[c].data());
  }
  std::array<float, 64 * 64> m{};
  ambisonicRotation(order, kRotations[3], m);
  rotateAmbisonic(order, m, ptrs.data(), frames);
  const auto rs = apply(kRotations[3], s);
  const Channels want = sh(order, rs[0], rs[1], rs[2]);
  for (size_t c = 0; c < 16; ++c)
    for (size_t t = 0; t < frames; ++t)
      CHECK(block[c][t] == Approx(want[c] * std::sin(0.3f * float(t) + 1.f)).margin(2e-5));
}
