// A door in a doorway between two rooms, source and listener on the line of sight through the
// doorway: closing it (gaps of 0, 5, 10 and 20 mm round the leaf) never makes the direct
// sound or the whole energy response louder than the open doorway, and what passes the gaps
// follows the slit model of engine/slit.h (Gomperts 1964; Mechel 1986), which this file
// computes on its own: the mouth impedance by quadrature of Bessel functions, the slit's line
// source by quadrature along each slit with the exact geometry (dpc: a power series and the
// paraxial Fresnel integral).
#include <algorithm>
#include <array>
#include <catch2/catch.hpp>
#include <cmath>
#include <complex>
#include <cstdio>
#include <glm/geometric.hpp>
#include <numbers>
#include <string>
#include <vector>

#include "engine/diffraction.h"
#include "engine/embree_tracer.h"
#include "engine/simulation.h"
#include "testing/test_scenes.h"

using namespace dpc;

namespace {

using C = std::complex<double>;
constexpr double kPi = std::numbers::pi;
constexpr float kC = 343.f;
const glm::vec3 kSource{3.f, 1.2f, 2.5f}, kListener{9.f, 1.2f, 2.5f};
constexpr float kDoorZ0 = 2.f, kDoorWidth = 1.f, kDoorHeight = 2.1f;  // doorway in x = 6

enum class Leaf { kNone, kStatic, kObject };

/// Two rooms 6 x 3 x 5 m along x, joined by the doorway (z 2..3, y 0..2.1) in the partition
/// x = 6 (double-sided sheets; the jambs end at the lintel), and the leaf: a sheet in the
/// doorway's plane leaving `gap` metres at both sides and the top, standing on the floor; in
/// the static mesh or as a scene object (as scenes/two_rooms.json has it). All opaque.
SceneDesc doorScene(float gap, Leaf leaf) {
  SceneDesc s = test::makeShoebox({12, 3, 5}, Bands(0.2f), 0.3f, kSource, kListener, 0.5f);
  const glm::vec3 y{0, 1, 0}, z{0, 0, 1};
  const float top = 3.f - kDoorHeight, right = 5.f - kDoorZ0 - kDoorWidth;
  test::addPanel(s.mesh, {6, 0, 0}, kDoorZ0 * z, kDoorHeight * y, 0);
  test::addPanel(s.mesh, {6, kDoorHeight, 0}, kDoorZ0 * z, top * y, 0);
  test::addPanel(s.mesh, {6, kDoorHeight, kDoorZ0}, kDoorWidth * z, top * y, 0);
  test::addPanel(s.mesh, {6, kDoorHeight, kDoorZ0 + kDoorWidth}, right * z, top * y, 0);
  test::addPanel(s.mesh, {6, 0, kDoorZ0 + kDoorWidth}, right * z, kDoorHeight * y, 0);
  const glm::vec3 corner{6.f, 0.f, kDoorZ0 + gap};
  const glm::vec3 along = (kDoorWidth - 2.f * gap) * z, up = (kDoorHeight - gap) * y;
  if (leaf == Leaf::kStatic) test::addPanel(s.mesh, corner, along, up, 0);
  if (leaf == Leaf::kObject) {
    ObjectDesc door;
    door.name = "leaf";
    test::addPanel(door.mesh, {0, 0, 0}, along, up, 0);
    door.trajectory = {ObjectKeyframe{0.0, corner, glm::quat(1, 0, 0, 0)}};
    s.objects.push_back(door);
  }
  s.propagation.raysPerFrame = 8192;
  s.propagation.maxOrder = 40;
  s.propagation.exactOrder = 0;
  s.propagation.irLength = 1.f;
  return s;
}

/// The direct sound (with edge diffraction) at the listener, band intensity relative to the
/// free field at the same distance; air ignored.
Bands directLevel(const SceneDesc& scene) {
  EmbreeTracer tracer(scene.mesh, scene.objects);
  const EdgeDiffraction diffraction(scene.mesh);
  const glm::vec3 v = kListener - kSource;
  const float dist = glm::length(v);
  DirectSound d;
  d.visible = !tracer.occluded(TraceRay{kSource, v / dist, 1e-3f, dist - 1e-3f});
  d.distance = dist;
  d.delaySeconds = dist / kC;
  d.direction = -v / dist;
  d.intensity = d.visible ? Bands(float(1.0 / (4 * kPi * dist * dist))) : Bands(0.f);
  diffraction.apply(tracer, kSource, ListenerSphere{kListener, 0.5f}, kC, Bands(0.f), d);
  return d.intensity * float(4 * kPi * dist * dist);
}

/// Gauss-Legendre, 8 points on [-1, 1].
constexpr std::array<double, 8> kGlX = {-0.9602898564975363, -0.7966664774136267,
                                        -0.5255324099163290, -0.1834346424956498,
                                        0.1834346424956498,  0.5255324099163290,
                                        0.7966664774136267,  0.9602898564975363};
constexpr std::array<double, 8> kGlW = {0.1012285362903763, 0.2223810344533745,
                                        0.3137066458778873, 0.3626837833783620,
                                        0.3626837833783620, 0.3137066458778873,
                                        0.2223810344533745, 0.1012285362903763};

/// The baffled strip's mouth impedance over omega rho per unit length, by quadrature of its
/// definition z_r(X) = (1 / X^2) int_0^X (X - t) (J0(t) - j Y0(t)) dt (t = X v^2 removes
/// Y0's logarithm at 0; 64 Gauss-Legendre panels in v), tabulated in log X.
class MouthImpedance {
 public:
  MouthImpedance() {
    for (int i = 0; i < kPoints; ++i) table_[size_t(i)] = direct(std::exp(kLogLo + i * kStep));
  }
  C operator()(double x) const {
    const double u = std::clamp((std::log(x) - kLogLo) / kStep, 0.0, double(kPoints - 1) - 1e-9);
    const size_t i = size_t(u);
    return table_[i] + (u - double(i)) * (table_[i + 1] - table_[i]);
  }

 private:
  static C direct(double x) {
    C sum = 0.0;
    constexpr int kPanels = 64;
    for (int p = 0; p < kPanels; ++p)
      for (size_t g = 0; g < kGlX.size(); ++g) {
        const double v = (p + 0.5 * (kGlX[g] + 1.0)) / kPanels, t = x * v * v;
        const C h(std::cyl_bessel_j(0.0, t), -std::cyl_neumann(0.0, t));
        sum += kGlW[g] * 0.5 / kPanels * (x - t) * h * 2.0 * x * v;
      }
    return sum / (x * x);
  }
  static constexpr int kPoints = 600;
  static constexpr double kLogLo = -11.0, kStep = (2.6 - kLogLo) / (kPoints - 1);  // X to 13.5
  std::array<C, kPoints> table_{};
};

/// One straight slit of the model: centre line from a to b, width w, in the wall x = 6.
struct Slit {
  glm::dvec3 a, b;
  double width;
};

/// The model's pressure at the listener re the free field's amplitude 1 / d: the sum over the
/// slits of int (j / 2 pi) t(X) D_S D_L e^{-jk(r + R)} / (r R) dz, t = 1 / z_r for a slit in a
/// sheet, X = k sin(beta) w, D = sinc(X sin(theta) / 2), by Gauss-Legendre panels of 1 cm.
C modelPressure(const std::vector<Slit>& slits, double k, const MouthImpedance& zr) {
  const glm::dvec3 S(kSource), L(kListener);
  C p = 0.0;
  for (const Slit& s : slits) {
    const glm::dvec3 e = glm::normalize(s.b - s.a);
    const double length = glm::length(s.b - s.a);
    const int panels = int(std::ceil(length / 0.01));
    auto sinFromAxis = [&](const glm::dvec3& v) {  // in the plane across the slit
      const glm::dvec3 across = v - glm::dot(v, e) * e;
      return std::abs(across.y * e.z - across.z * e.y) / glm::length(across);  // not along x
    };
    for (int n = 0; n < panels; ++n)
      for (size_t g = 0; g < kGlX.size(); ++g) {
        const double z = (n + 0.5 * (kGlX[g] + 1.0)) * length / panels;
        const glm::dvec3 P = s.a + z * e;
        const double r = glm::length(P - S), R = glm::length(L - P);
        const double sinBeta = glm::length(glm::cross((P - S) / r, e));
        const double x = k * sinBeta * s.width;
        auto sinc = [](double u) { return std::abs(u) < 1e-9 ? 1.0 : std::sin(u) / u; };
        const double directivity =
            sinc(0.5 * x * sinFromAxis(P - S)) * sinc(0.5 * x * sinFromAxis(L - P));
        p += kGlW[g] * 0.5 * length / panels * C(0.0, 1.0) / (2 * kPi) / zr(x) * directivity *
             std::polar(1.0 / (r * R), -k * (r + R));
      }
  }
  return p * double(glm::length(L - S));
}

/// The model's band levels (dB re the free field): |p|^2 averaged over the band's
/// frequencies, the slits centred in the gaps round the leaf.
Bands modelLevels(double gap, const MouthImpedance& zr) {
  const double z0 = kDoorZ0, z1 = kDoorZ0 + kDoorWidth, h = kDoorHeight;
  const std::vector<Slit> slits = {{{6, 0, z0 + gap / 2}, {6, h, z0 + gap / 2}, gap},
                                   {{6, 0, z1 - gap / 2}, {6, h, z1 - gap / 2}, gap},
                                   {{6, h - gap / 2, z0}, {6, h - gap / 2, z1}, gap}};
  Bands out;
  for (int b = 0; b < kNumBands; ++b) {
    double mean = 0.0;
    for (int i = 0; i < kDiffractionFrequenciesPerBand; ++i) {
      const double k = 2 * kPi * diffractionFrequencyHz(b, i) / kC;
      mean += std::norm(modelPressure(slits, k, zr)) / kDiffractionFrequenciesPerBand;
    }
    out[b] = float(10 * std::log10(mean));
  }
  return out;
}

Bands decibels(const Bands& x) {
  Bands out;
  for (int b = 0; b < kNumBands; ++b) out[b] = float(10 * std::log10(std::max(double(x[b]), 1e-30)));
  return out;
}

}  // namespace

TEST_CASE("Door gaps: closed is never louder than open, and the gaps pass what the slit model says",
          "[diffraction][door]") {
  const MouthImpedance zr;
  const Bands open = decibels(directLevel(doorScene(0.f, Leaf::kNone)));
  std::printf("door open: direct re free field (dB) ");
  for (int b = 0; b < kNumBands; ++b) std::printf(" %6.1f", double(open[b]));
  std::printf("\n");
  for (Leaf leaf : {Leaf::kStatic, Leaf::kObject})
    for (float gap : {0.f, 0.005f, 0.01f, 0.02f}) {
      const Bands closed = decibels(directLevel(doorScene(gap, leaf)));
      const Bands model = gap > 0.f ? modelLevels(gap, zr) : Bands(-300.f);
      std::printf("leaf %-6s gap %2.0f mm: closed / model (dB) ",
                  leaf == Leaf::kStatic ? "static" : "object", double(gap) * 1e3);
      for (int b = 0; b < kNumBands; ++b)
        std::printf(" %6.1f/%6.1f", double(closed[b]), double(model[b]));
      std::printf("\n");
      for (int b = 0; b < kNumBands; ++b) {
        // Closing the door adds no energy: below the open doorway and the free field.
        CHECK(closed[b] <= open[b]);
        CHECK(closed[b] <= 1e-4f);
        // The gap's level within 3 dB of the model per octave (dpc: the probed width, within
        // 12 % of the gap's, and the paraxial line integral; the model: the exact geometry).
        if (gap > 0.f) CHECK(std::abs(closed[b] - model[b]) < 3.0);
      }
    }
}
