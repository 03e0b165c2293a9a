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
#include "engine/geometry.h"
#include "engine/propagation.h"
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
/// the static mesh or as a scene object (as scenes/two_rooms.json has it). All opaque, of
/// absorption `alpha`.
SceneDesc doorScene(float gap, Leaf leaf, float alpha = 0.2f) {
  SceneDesc s = test::makeShoebox({12, 3, 5}, Bands(alpha), 0.3f, kSource, kListener, 0.5f);
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
constexpr std::array<double, 8> kGlX = {
    -0.9602898564975363, -0.7966664774136267, -0.5255324099163290, -0.1834346424956498,
    0.1834346424956498,  0.5255324099163290,  0.7966664774136267,  0.9602898564975363};
constexpr std::array<double, 8> kGlW = {0.1012285362903763, 0.2223810344533745, 0.3137066458778873,
                                        0.3626837833783620, 0.3626837833783620, 0.3137066458778873,
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
  for (int b = 0; b < kNumBands; ++b)
    out[b] = float(10 * std::log10(std::max(double(x[b]), 1e-30)));
  return out;
}

}  // namespace

/// One row of the markdown table in docs/validation.md: gap, what, eight band levels (dB).
void tableRow(const char* gap, const char* what, const Bands& level) {
  std::printf("| %s | %s |", gap, what);
  for (int b = 0; b < kNumBands; ++b)
    std::printf(level[b] < -200.f ? " - |" : " %.1f |", double(level[b]));
  std::printf("\n");
}

TEST_CASE("Door gaps: closed is never louder than open, and the gaps pass what the slit model says",
          "[diffraction][door]") {
  // Prints docs/validation.md's table of the gaps (the lines beginning with "|").
  const MouthImpedance zr;
  const Bands open = decibels(directLevel(doorScene(0.f, Leaf::kNone)));
  std::printf(
      "| gap | direct re free field (dB) | 63 Hz | 125 | 250 | 500 | 1k | 2k | 4k | 8k |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|\n");
  tableRow("-", "open doorway (UTD)", open);
  for (float gap : {0.f, 0.005f, 0.01f, 0.02f}) {
    const Bands model = gap > 0.f ? modelLevels(gap, zr) : Bands(-300.f);
    const std::string mm = std::to_string(int(std::lround(gap * 1e3f))) + " mm";
    for (Leaf leaf : {Leaf::kStatic, Leaf::kObject}) {
      const Bands closed = decibels(directLevel(doorScene(gap, leaf)));
      tableRow(mm.c_str(),
               leaf == Leaf::kStatic ? "closed, leaf in the mesh" : "closed, leaf an object",
               closed);
      for (int b = 0; b < kNumBands; ++b) {
        // Closing the door adds no energy: below the open doorway and the free field.
        CHECK(closed[b] <= open[b]);
        CHECK(closed[b] <= 1e-4f);
        // The gap's level within 3 dB of the model per octave (dpc: the probed width, within
        // 5 % of the gap's, and the paraxial line integral; the model: the exact geometry).
        if (gap > 0.f) CHECK(std::abs(closed[b] - model[b]) < 3.0);
      }
    }
    if (gap > 0.f) tableRow(mm.c_str(), "slit model (this test)", model);
  }
}

namespace {

/// The whole energy response at the listener per band (1/m^2): the estimator's bins plus the
/// direct sound, the mean of `frames` frames of a fixed seed.
Bands totalEnergy(const SceneDesc& scene, int frames) {
  Simulation sim(scene);
  Bands total(0.f);
  for (int f = 0; f < frames; ++f) {
    sim.runFrame(kListener);
    const auto& r = sim.result(0);
    for (const Bands& bin : r.energy.bins()) total += bin;
    total += r.direct.intensity;
  }
  return total * (1.f / float(frames));
}

}  // namespace

TEST_CASE("Door gaps: the whole energy response is never louder closed than open",
          "[diffraction][door]") {
  // Nearly anechoic rooms (absorption 0.9), so that the direct sound weighs in the total as
  // much as the reflections do. The ray-traced part's Monte Carlo error (10 frames of 8192
  // rays: a few per cent) is far below the margins, so the comparison is strict.
  constexpr int kFrames = 10;
  constexpr float kAlpha = 0.9f;
  const Bands open = decibels(totalEnergy(doorScene(0.f, Leaf::kNone, kAlpha), kFrames));
  for (float gap : {0.f, 0.005f, 0.01f, 0.02f}) {
    const Bands closed = decibels(totalEnergy(doorScene(gap, Leaf::kObject, kAlpha), kFrames));
    std::printf("total, gap %2.0f mm: closed - open (dB)", double(gap) * 1e3);
    for (int b = 0; b < kNumBands; ++b) std::printf(" %6.1f", double(closed[b] - open[b]));
    std::printf("\n");
    for (int b = 0; b < kNumBands; ++b) CHECK(closed[b] <= open[b]);
  }
}

TEST_CASE("Door gaps: scenes/two_rooms.json's talker is clearly quieter at b with the door shut",
          "[diffraction][door]") {
  // The talker in room A, listener b in room B without line of sight through the doorway;
  // the door (a leaf object with 1 cm gaps, transmitting) open at 2 s, shut at 7 s.
  const SceneDesc scene = loadScene(std::string(DPC_SOURCE_DIR) + "/scenes/two_rooms.json");
  Geometry geometry(scene.mesh, scene.materials, scene.propagation.patchSize, scene.objects);
  EmbreeTracer tracer(scene.mesh, scene.objects);
  const EdgeDiffraction diffraction(scene.mesh);
  Propagator prop(geometry, tracer, scene.propagation);
  const SourceDesc& talker = scene.sources[0];
  const glm::vec3 forward = sourceForward(sourceRotationAt(talker, 0.0));
  const ListenerSphere b{scene.listeners[1].position, scene.listeners[1].radius};
  auto direct = [&](double t) {
    tracer.setObjectPose(0, objectPoseAt(scene.objects[0], t));
    tracer.commitPoses();
    DirectSound d = prop.directSound(talker.position, b, talker.directivity, forward);
    diffraction.apply(tracer, talker.position, b, scene.propagation.speedOfSound,
                      prop.airAttenuationPerMetre(), d, talker.directivity, forward);
    return decibels(d.intensity);
  };
  const Bands open = direct(2.0), shut = direct(7.0);
  std::printf("two_rooms talker -> b direct (dB re 1/m^2):\n  open");
  for (int b = 0; b < kNumBands; ++b) std::printf(" %6.1f", double(open[b]));
  std::printf("\n  shut");
  for (int b = 0; b < kNumBands; ++b) std::printf(" %6.1f", double(shut[b]));
  std::printf("\n");
  // "Clearly": at least 3 dB (twice the power) in every band. The gaps and the partition's
  // transmission keep it from more at 63 Hz (slit model: a 1 cm slit passes about 10 times
  // its area there) and at 8 kHz (the slits radiate into the jamb's shadow about as strongly
  // as the open doorway's edge diffracts into it).
  for (int b = 0; b < kNumBands; ++b) CHECK(shut[b] < open[b] - 3.f);
}

TEST_CASE("Door gaps: an obstacle in a window never lifts the direct sound above the free field",
          "[diffraction][door]") {
  // A 1 m square window in a free-standing wall (four rims), a 10 cm plate in its middle (an
  // object: no edges of its own) blocking the line of sight. The four rims see the listener
  // on their lit side; near their shadow boundaries each one's UTD field is about minus half
  // the incident one, which sum to more than the free field at low frequencies. With the line
  // of sight blocked the result is held at the free field.
  SceneDesc s;
  s.materials.push_back(Material{"wall", Bands(0.1f), Bands(0.f)});
  const glm::vec3 y{0, 1, 0}, z{0, 0, 1};
  test::addPanel(s.mesh, {6, -20, -20}, 40.f * z, 19.5f * y, 0);    // below the window
  test::addPanel(s.mesh, {6, 0.5f, -20}, 40.f * z, 19.5f * y, 0);   // above
  test::addPanel(s.mesh, {6, -0.5f, -20}, 19.5f * z, 1.f * y, 0);   // left
  test::addPanel(s.mesh, {6, -0.5f, 0.5f}, 19.5f * z, 1.f * y, 0);  // right
  ObjectDesc plate;
  plate.name = "plate";
  test::addPanel(plate.mesh, {0, -0.05f, -0.05f}, 0.1f * z, 0.1f * y, 0);
  plate.trajectory = {ObjectKeyframe{0.0, {6.f, 0.f, 0.f}, glm::quat(1, 0, 0, 0)}};
  s.objects.push_back(plate);
  EmbreeTracer tracer(s.mesh, s.objects);
  const EdgeDiffraction diffraction(s.mesh);
  const glm::vec3 src{3.f, 0.f, 0.f}, lis{9.f, 0.f, 0.f};
  DirectSound d;  // blocked by the plate
  d.distance = 6.f;
  d.delaySeconds = 6.f / kC;
  d.direction = {-1.f, 0.f, 0.f};
  REQUIRE(tracer.occluded(TraceRay{src, {1.f, 0.f, 0.f}, 1e-3f, 6.f - 1e-3f}));
  // The window's four rims and the wall's far outer rims, 20 m away.
  REQUIRE(diffraction.apply(tracer, src, ListenerSphere{lis, 0.5f}, kC, Bands(0.f), d) >= 4);
  const Bands level = decibels(d.intensity * float(4 * kPi * 36.0));
  std::printf("window with a plate: direct re free field (dB)");
  for (int b = 0; b < kNumBands; ++b) std::printf(" %6.1f", double(level[b]));
  std::printf("\n");
  for (int b = 0; b < kNumBands; ++b) CHECK(level[b] <= 1e-4f);
}
