#include "audio/vbap.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace dpc::audio {
namespace {

using Vec = std::array<double, 3>;
constexpr double kDeg = std::numbers::pi / 180.0;

Vec unit(double azDeg, double elDeg) {
  return {std::cos(elDeg * kDeg) * std::cos(azDeg * kDeg),
          std::cos(elDeg * kDeg) * std::sin(azDeg * kDeg), std::sin(elDeg * kDeg)};
}
Vec sub(const Vec& a, const Vec& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
double dot(const Vec& a, const Vec& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
Vec cross(const Vec& a, const Vec& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

/// The inverse of the 3 x 3 matrix with rows a, b, c (row-major); false if singular.
bool invert(const Vec& a, const Vec& b, const Vec& c, std::array<double, 9>& inv) {
  const Vec bc = cross(b, c), ca = cross(c, a), ab = cross(a, b);
  const double det = dot(a, bc);
  if (std::abs(det) < 1e-9) return false;
  // (rows a, b, c)^-1 has the columns bc, ca, ab over det.
  for (int r = 0; r < 3; ++r) {
    inv[size_t(3 * r + 0)] = bc[size_t(r)] / det;
    inv[size_t(3 * r + 1)] = ca[size_t(r)] / det;
    inv[size_t(3 * r + 2)] = ab[size_t(r)] / det;
  }
  return true;
}

}  // namespace

Vbap::Vbap(std::span<const std::array<double, 2>> directionsDegrees) {
  if (directionsDegrees.size() < 2) throw std::invalid_argument("VBAP needs two loudspeakers");
  planar_ = true;
  for (const auto& d : directionsDegrees) {
    if (!std::isfinite(d[0]) || !std::isfinite(d[1]))
      throw std::invalid_argument("loudspeaker angle is not a finite number");
    speakers_.push_back(unit(d[0], d[1]));
    planar_ = planar_ && std::abs(d[1]) < 1e-9;
  }
  real_ = speakers_.size();
  for (size_t i = 0; i < real_; ++i)
    for (size_t j = i + 1; j < real_; ++j)
      if (dot(speakers_[i], speakers_[j]) > std::cos(1.0 * kDeg))
        throw std::invalid_argument("two loudspeakers within 1 degree of each other");
  if (planar_)
    buildPairs();
  else
    buildHull();
}

void Vbap::buildPairs() {
  std::vector<int> order(real_);
  for (size_t i = 0; i < real_; ++i) order[i] = int(i);
  auto az = [&](int i) { return std::atan2(speakers_[size_t(i)][1], speakers_[size_t(i)][0]); };
  std::sort(order.begin(), order.end(), [&](int a, int b) { return az(a) < az(b); });
  for (size_t k = 0; k < real_; ++k) {
    const int a = order[k], b = order[(k + 1) % real_];
    // A pair wider than 180 degrees (two loudspeakers in front only) cannot pan the rear.
    std::array<double, 9> inv{};
    const Vec up{0, 0, 1};
    if (!invert(speakers_[size_t(a)], speakers_[size_t(b)], up, inv)) continue;
    faces_.push_back({a, b, -1});
    inverses_.push_back(inv);
  }
}

void Vbap::buildHull() {
  double lowest = 90, highest = -90;
  for (const Vec& s : speakers_) {
    lowest = std::min(lowest, std::asin(s[2]) / kDeg);
    highest = std::max(highest, std::asin(s[2]) / kDeg);
  }
  if (lowest > -45) speakers_.push_back({0, 0, -1});
  if (highest < 45) speakers_.push_back({0, 0, 1});
  // Brute-force hull on slightly perturbed points (deterministic), so that four coplanar
  // loudspeakers (a symmetric ring) give two triangles, not four overlapping ones.
  std::vector<Vec> p = speakers_;
  for (size_t i = 0; i < p.size(); ++i)
    for (size_t k = 0; k < 3; ++k) p[i][k] += 1e-7 * std::sin(double(7 * i + 3 * k + 1));
  const size_t n = p.size();
  for (size_t i = 0; i < n; ++i)
    for (size_t j = i + 1; j < n; ++j)
      for (size_t k = j + 1; k < n; ++k) {
        const Vec normal = cross(sub(p[j], p[i]), sub(p[k], p[i]));
        int above = 0, below = 0;
        for (size_t m = 0; m < n; ++m) {
          if (m == i || m == j || m == k) continue;
          const double s = dot(normal, sub(p[m], p[i]));
          above += s > 0;
          below += s < 0;
        }
        std::array<double, 9> inv{};
        if ((above == 0 || below == 0) && invert(speakers_[i], speakers_[j], speakers_[k], inv)) {
          faces_.push_back({int(i), int(j), int(k)});
          inverses_.push_back(inv);
        }
      }
  if (faces_.empty()) throw std::invalid_argument("the loudspeakers span no triangle");
  addOtherDiagonals();
}

void Vbap::addOtherDiagonals() {
  hullFaces_ = faces_.size();
  otherSplit_.assign(hullFaces_, -1);
  auto has = [](const std::array<int, 3>& face, int s) {
    return std::find(face.begin(), face.end(), s) != face.end();
  };
  for (size_t f = 0; f < hullFaces_; ++f)
    for (size_t h = f + 1; h < hullFaces_; ++h) {
      const auto& a = faces_[f];
      const auto& b = faces_[h];
      // c: a's vertex off the shared edge, d: b's; the other diagonal is c-d.
      const auto c = std::find_if(a.begin(), a.end(), [&](int s) { return !has(b, s); });
      const auto d = std::find_if(b.begin(), b.end(), [&](int s) { return !has(a, s); });
      if (std::count_if(a.begin(), a.end(), [&](int s) { return has(b, s); }) != 2) continue;
      if (size_t(std::max({a[0], a[1], a[2], *d})) >= real_) continue;  // real loudspeakers only
      const Vec& o = speakers_[size_t(a[0])];
      const Vec normal = cross(sub(speakers_[size_t(a[1])], o), sub(speakers_[size_t(a[2])], o));
      const Vec toD = sub(speakers_[size_t(*d)], o);
      if (std::abs(dot(normal, toD)) > 1e-9 * std::sqrt(dot(normal, normal) * dot(toD, toD)))
        continue;  // not one plane
      std::array<std::array<int, 3>, 2> split{};
      std::array<std::array<double, 9>, 2> inv{};
      int k = 0;
      for (int e : a)
        if (e != *c) split[size_t(k)] = {*c, *d, e}, ++k;
      bool ok = true;
      for (size_t t = 0; t < 2; ++t)
        ok = ok && invert(speakers_[size_t(split[t][0])], speakers_[size_t(split[t][1])],
                          speakers_[size_t(split[t][2])], inv[t]);
      if (!ok) continue;
      otherSplit_[f] = otherSplit_[h] = int(faces_.size());
      for (size_t t = 0; t < 2; ++t) {
        faces_.push_back(split[t]);
        inverses_.push_back(inv[t]);
      }
    }
}

void Vbap::addOtherSplit(size_t f, const Vec& p, std::span<float> out) const {
  std::array<double, 3> g{};
  for (int k = 0; k < 2; ++k) {
    const size_t t = size_t(otherSplit_[f] + k);
    if (!faceGains(t, p, g)) continue;
    for (int c = 0; c < 3; ++c)
      out[size_t(faces_[t][size_t(c)])] += float(std::max(0.0, g[size_t(c)]));
    return;
  }
}

void Vbap::shareImaginary(const std::array<int, 3>& face, std::span<float> out) const {
  // At an imaginary loudspeaker: equal power over the real ones of every face around it.
  int imaginary = -1;
  for (int s : face)
    if (s >= 0 && size_t(s) >= real_) imaginary = s;
  size_t count = 0;
  for (const auto& f : faces_)
    if (std::find(f.begin(), f.end(), imaginary) != f.end())
      for (int s : f)
        if (s >= 0 && size_t(s) < real_ && out[size_t(s)] == 0.f) out[size_t(s)] = 1.f, ++count;
  for (size_t i = 0; i < real_; ++i) out[i] /= float(std::sqrt(double(std::max<size_t>(count, 1))));
}

bool Vbap::faceGains(size_t f, const Vec& p, std::array<double, 3>& g) const {
  const std::array<double, 9>& inv = inverses_[f];
  for (int c = 0; c < 3; ++c)
    g[size_t(c)] = p[0] * inv[size_t(c)] + p[1] * inv[size_t(3 + c)] + p[2] * inv[size_t(6 + c)];
  const int used = planar_ ? 2 : 3;
  for (int c = 0; c < used; ++c)
    if (g[size_t(c)] < -1e-9) return false;
  return true;
}

void Vbap::gains(const float dir[3], std::span<float> out) const {
  std::fill(out.begin(), out.begin() + long(real_), 0.f);
  Vec p{dir[0], dir[1], planar_ ? 0.0 : dir[2]};
  const double len = std::sqrt(dot(p, p));
  if (!(len > 1e-12) || !std::isfinite(len)) {
    if (planar_ && std::abs(dir[2]) > 0) {  // straight up or down over a horizontal ring
      for (size_t i = 0; i < real_; ++i) out[i] = float(1.0 / std::sqrt(double(real_)));
      return;
    }
    p = {1, 0, 0};
  } else {
    for (double& x : p) x /= len;
  }
  std::array<double, 3> g{};
  const size_t hull = planar_ ? faces_.size() : hullFaces_;
  size_t f = 0;
  while (f < hull && !faceGains(f, p, g)) ++f;
  if (f == hull) return;  // outside every pair: a layout with a gap beyond 180 deg
  for (int c = 0; c < 3; ++c) {
    const int s = faces_[f][size_t(c)];
    if (s < 0 || size_t(s) >= real_) continue;  // the 2-D helper axis, an imaginary speaker
    out[size_t(s)] = float(std::max(0.0, g[size_t(c)]));
  }
  // A face of four (real loudspeakers only: imaginary ones close the hull alone): both splits.
  if (!planar_ && otherSplit_[f] >= 0) addOtherSplit(f, p, out);
  double sum = 0;
  for (size_t i = 0; i < real_; ++i) sum += double(out[i]) * out[i];
  if (sum <= 0) return shareImaginary(faces_[f], out);
  const float norm = float(1.0 / std::sqrt(sum));
  for (size_t i = 0; i < real_; ++i) out[i] *= norm;
}

}  // namespace dpc::audio
