// Edge diffraction (engine/diffraction.h) against the thin-barrier result, the exact
// Biot-Tolstoy-Medwin wedge solution and UTD's own boundary properties.
#include "engine/diffraction.h"

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <complex>
#include <cstdio>
#include <glm/geometric.hpp>
#include <numbers>
#include <string>
#include <vector>

#include "engine/embree_tracer.h"
#include "engine/geometry.h"
#include "engine/propagation.h"
#include "scene/scene.h"
#include "testing/test_scenes.h"

using namespace dpc;

namespace {

constexpr float kC = 343.f;

/// Thin rigid screen in the plane x = 0, top edge y = 0, reaching far down and sideways.
Mesh screen() {
  Mesh m;
  m.vertices = {{0, 0, -500}, {0, 0, 500}, {0, -500, 500}, {0, -500, -500}};
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  m.materialIndex = {0, 0};
  return m;
}

struct Setup {
  Mesh mesh;
  EmbreeTracer tracer;
  EdgeDiffraction diffraction;
  explicit Setup(Mesh m) : mesh(std::move(m)), tracer(mesh), diffraction(mesh) {}
  /// Band levels (dB) relative to the free field at the direct distance, air ignored.
  Bands levels(glm::vec3 src, glm::vec3 lis) {
    ListenerSphere l{lis, 0.01f};
    DirectSound d;
    const glm::vec3 v = src - lis;
    const float dist = glm::length(v);
    d.visible = !tracer.occluded(TraceRay{lis, v / dist, 1e-3f, dist - 1e-3f});
    d.distance = dist;
    d.delaySeconds = dist / kC;
    d.direction = v / dist;
    d.intensity = d.visible ? Bands(float(1.0 / (4 * std::numbers::pi * dist * dist))) : Bands(0.f);
    diffraction.apply(tracer, src, l, kC, Bands(0.f), d);
    Bands out;
    for (int b = 0; b < kNumBands; ++b)
      out[b] = float(10 * std::log10(double(d.intensity[b]) * 4 * std::numbers::pi * dist * dist));
    return out;
  }
};

/// Kurze & Anderson (1971) closed form of Maekawa's (1968) thin-screen insertion loss, dB:
/// 5 + 20 log10( sqrt(2 pi N) / tanh sqrt(2 pi N) ), N = 2 delta / lambda.
double kurzeAnderson(double n) {
  const double x = std::sqrt(2 * std::numbers::pi * n);
  return 5 + 20 * std::log10(x / std::tanh(x));
}

/// Solid wedge along the z axis (|z| <= 100 m), air wedge [0, open] (open > pi, radians):
/// face 0 the half-plane y = 0, x > 0; face 1 at angle `open`; closed 60 m from the edge and
/// by end caps, so its other edges are far and their paths weak.
Mesh solidWedge(double open) {
  constexpr float kZ = 100.f, kD = 60.f;
  const glm::vec2 a{kD, 0.f}, b{kD * float(std::cos(open)), kD * float(std::sin(open))};
  Mesh m;
  m.vertices = {{0, 0, -kZ}, {0, 0, kZ}, {a.x, a.y, -kZ}, {a.x, a.y, kZ}, {b.x, b.y, -kZ},
                {b.x, b.y, kZ}};
  m.triangles = {{0, 2, 3}, {0, 3, 1}, {0, 5, 4}, {0, 1, 5},
                 {2, 4, 5}, {2, 5, 3}, {0, 4, 2}, {1, 3, 5}};
  m.materialIndex.assign(m.triangles.size(), 0);
  return m;
}

/// Exact transfer function of the first-order diffracted field of an infinite rigid wedge
/// (open angle theta_w) for a point source, from the Biot-Tolstoy-Medwin impulse response
/// (U. P. Svensson, R. I. Fred & J. Vanderkooy, "An analytic secondary source model of edge
/// diffraction impulse responses", JASA 106(5), 1999, eq. 1; free-field response 1/r):
///   h(t) = -(c nu / 2 pi) beta(eta) / (rS rR sinh eta),  t > tau0 = sqrt((rS+rR)^2 + dz^2)/c,
///   cosh eta = (c^2 t^2 - rS^2 - rR^2 - dz^2) / (2 rS rR),  nu = pi / theta_w,
///   beta = sum over the four signs of sin(nu (pi +- thS +- thR)) / (cosh(nu eta) - cos(...)).
/// H(f) = int h(t) e^{-j 2 pi f t} dt over 0.1 s after tau0 (the tail falls as t^{-2(1+nu)}),
/// with t = tau0 + u^2 to remove the 1 / sqrt(t - tau0) onset, 8-point Gauss-Legendre panels
/// at most 0.5 rad of the highest frequency wide. Receivers off the zone boundaries only.
std::vector<std::complex<double>> btmTransfer(double open, double rS, double thS, double rR,
                                              double thR, double dz,
                                              const std::vector<double>& freqs) {
  const double c = kC, nu = std::numbers::pi / open;
  const double tau0 = std::sqrt((rS + rR) * (rS + rR) + dz * dz) / c;
  const double angles[4] = {std::numbers::pi + thS + thR, std::numbers::pi + thS - thR,
                            std::numbers::pi - thS + thR, std::numbers::pi - thS - thR};
  static const double x[8] = {-0.9602898564975363, -0.7966664774136267, -0.5255324099163290,
                              -0.1834346424956498, 0.1834346424956498,  0.5255324099163290,
                              0.7966664774136267,  0.9602898564975363};
  static const double w[8] = {0.1012285362903763, 0.2223810344533745, 0.3137066458778873,
                              0.3626837833783620, 0.3626837833783620, 0.3137066458778873,
                              0.2223810344533745, 0.1012285362903763};
  double wMax = 0.0;
  for (double f : freqs) wMax = std::max(wMax, 2 * std::numbers::pi * f);
  std::vector<std::complex<double>> h(freqs.size());
  const double uEnd = std::sqrt(0.1);
  for (double u = 0.0; u < uEnd;) {
    const double du = std::min({1e-3, 0.5 / (2 * wMax * std::max(u, 1e-9)), uEnd - u});
    for (int g = 0; g < 8; ++g) {
      const double uu = u + (x[g] + 1) / 2 * du;
      // cosh eta - 1 = q = u^2 A without cancellation; sinh eta = u sqrt(A (q + 2)).
      const double A = c * c * (2 * tau0 + uu * uu) / (2 * rS * rR), q = uu * uu * A;
      const double eta = std::log1p(q + std::sqrt(q * (q + 2)));
      double beta = 0.0;
      for (double a : angles) beta += std::sin(nu * a) / (std::cosh(nu * eta) - std::cos(nu * a));
      // h dt = h 2u du; 2u / sinh eta = 2 / sqrt(A (q + 2)).
      const double value = -(c * nu / (2 * std::numbers::pi)) * beta / (rS * rR) * 2 /
                           std::sqrt(A * (q + 2)) * w[g] * du / 2;
      const double t = tau0 + uu * uu;
      for (size_t i = 0; i < freqs.size(); ++i)
        h[i] += value * std::polar(1.0, -2 * std::numbers::pi * freqs[i] * t);
    }
    u += du;
  }
  return h;
}

}  // namespace

TEST_CASE("Diffraction: edges found at load time", "[diffraction]") {
  const EdgeDiffraction s(screen());
  CHECK(s.edges().size() == 4);  // the four rims; the coplanar diagonal is no wedge
  for (const auto& e : s.edges()) CHECK(e.open == Approx(2 * std::numbers::pi));
  const EdgeDiffraction box(test::solidBox(2.f));
  CHECK(box.edges().size() == 12);  // diagonals of the faces are flat
  // 90 or 270 degrees from face 0 depending on the winding; either way the wedges are
  // pi/2 (the solid) and 3 pi/2 (the air round it).
  for (const auto& e : box.edges())
    CHECK(std::min(e.open, float(2 * std::numbers::pi) - e.open) ==
          Approx(0.5 * std::numbers::pi).margin(1e-4));
}

TEST_CASE("Diffraction: a box written with a corner per face has the same 12 edges",
          "[diffraction]") {
  // Exporters often write each face's corners separately; edges must be matched by position,
  // or every edge of a solid becomes two coincident thin screens (open angle 2 pi) and the
  // diffracted sound is counted twice.
  const Mesh shared = test::solidBox(2.f);
  Mesh split;
  for (const auto& t : shared.triangles) {
    const uint32_t base = uint32_t(split.vertices.size());
    for (uint32_t v : t) split.vertices.push_back(shared.vertices[v]);
    split.triangles.push_back({base, base + 1, base + 2});
    split.materialIndex.push_back(0);
  }
  const EdgeDiffraction a(shared), b(split);
  REQUIRE(b.edges().size() == a.edges().size());
  // The same segments (either end first) with the same wedge (open or 2 pi - open: which
  // side holds air is decided per frame).
  auto wedge = [](float open) { return std::min(open, float(2 * std::numbers::pi) - open); };
  for (const auto& e : a.edges()) {
    const auto match = std::find_if(b.edges().begin(), b.edges().end(), [&](const auto& f) {
      return (f.a == e.a && f.b == e.b) || (f.a == e.b && f.b == e.a);
    });
    REQUIRE(match != b.edges().end());
    CHECK(wedge(match->open) == Approx(wedge(e.open)).margin(1e-6));
  }
}

TEST_CASE("Diffraction: thin screen follows Kurze-Anderson across Fresnel numbers",
          "[diffraction]") {
  Setup s(screen());
  // Source 5 m before the screen, 1 m below its top; listener 5 m behind at depth y.
  const glm::vec3 src{-5.f, -1.f, 0.f};
  double worst = 0.0;
  for (float y : {-0.3f, -0.6f, -1.f, -1.5f, -1.9f, -2.5f, -4.f}) {  // N 0.12 .. 9.5
    const glm::vec3 lis{5.f, y, 0.f};
    const double delta = double(glm::length(src) + glm::length(lis) - glm::length(lis - src));
    const Bands lv = s.levels(src, lis);
    for (int b = 1; b <= 6; ++b) {  // 125 Hz .. 4 kHz
      const double lambda = kC / bandCentreExactHz(b);
      const double n = 2 * delta / lambda;
      if (n < 0.1 || n > 10.0) continue;
      const double il = -double(lv[b]), ref = kurzeAnderson(n);
      std::printf("screen: y %5.2f band %4.0f Hz N %6.3f  UTD IL %5.2f dB  K-A %5.2f dB  %+5.2f\n",
                  double(y), bandCentreExactHz(b), n, il, ref, il - ref);
      worst = std::max(worst, std::abs(il - ref));
      // Allowance 2.5 dB: Kurze-Anderson fits Maekawa's measured chart, which scatters by
      // about 1.5 dB and gives 5 dB at N -> 0 where every exact wedge theory (and UTD) gives
      // 6 dB; UTD is asymptotically exact for large kL, so the gap closes as N grows.
      CHECK(std::abs(il - ref) < 2.5);
    }
  }
  std::printf("screen: worst |UTD - Kurze-Anderson| %.2f dB\n", worst);
}

TEST_CASE("Diffraction: continuous across the shadow boundary, -6 dB on it", "[diffraction]") {
  for (int which = 0; which < 2; ++which) {
    // A screen (half-plane) and a 90-degree corner of a solid box.
    Setup s(which == 0 ? screen() : test::solidBox(2.f));
    const glm::vec3 src = which == 0 ? glm::vec3{-5.f, -1.f, 0.f} : glm::vec3{-3.f, 1.f, 1.f};
    const glm::vec3 edgePoint = which == 0 ? glm::vec3{0.f, 0.f, 0.f} : glm::vec3{0.f, 2.f, 1.f};
    // Shadow boundary behind the edge: the line from the source through the edge, listener
    // 5 m beyond it, stepped across in 1 mm steps.
    const glm::vec3 dir = glm::normalize(edgePoint - src);
    const glm::vec3 across = glm::normalize(glm::cross(dir, glm::vec3(0, 0, 1)));
    const glm::vec3 onBoundary = edgePoint + 5.f * dir;
    Bands prev = s.levels(src, onBoundary - 0.05f * across);
    double maxStep = 0.0;
    for (int i = -49; i <= 50; ++i) {
      const Bands lv = s.levels(src, onBoundary + 0.001f * float(i) * across);
      for (int b = 0; b < kNumBands; ++b)
        maxStep = std::max(maxStep, double(std::abs(lv[b] - prev[b])));
      prev = lv;
    }
    const Bands at = s.levels(src, onBoundary + 1e-4f * across);
    std::printf("%s: largest step over 1 mm across the boundary %.3f dB; on it %.2f dB (1 kHz)\n",
                which == 0 ? "screen" : "corner", maxStep, double(at[4]));
    // The steepest the level can change: about 6 dB across a Fresnel zone, sqrt(lambda d1 d2 /
    // (d1 + d2)) = 0.2 m at 8 kHz here (d1 3-5 m to the edge, d2 5 m beyond), so 0.03 dB per
    // mm; 0.1 dB allows the band's upper frequencies and single-precision geometry. A step in
    // how a band's frequencies are evaluated (UTD coefficients held constant between the
    // frequencies they were computed at) shows as steps of 0.8 dB here.
    CHECK(maxStep < 0.1);
    // UTD: at the shadow boundary the total field tends to half the incident one
    // (-6.02 dB) for any wedge as kL grows; the non-singular terms add a relative amplitude
    // of order (2 pi k L)^-1/2 (0.05 at 4 kHz here, +-0.5 dB): checked at 4 and 8 kHz.
    for (int b = 6; b < kNumBands; ++b) CHECK(std::abs(at[b] + 6.02) < 1.0);
  }
}

TEST_CASE("Diffraction: level behind a screen vs position (writes diffraction_screen.csv)",
          "[diffraction]") {
  // Listener 5 m behind the screen from 1 m above the shadow boundary's height to 4 m below
  // the edge; source 5 m before it, 1 m below the edge. The CSV feeds
  // scripts/plot_diffraction.py (docs/images/diffraction-screen.png).
  Setup s(screen());
  const glm::vec3 src{-5.f, -1.f, 0.f};
  const std::string path = std::string(DPC_BINARY_DIR) + "/diffraction_screen.csv";
  FILE* f = std::fopen(path.c_str(), "w");
  REQUIRE(f);
  std::fprintf(f, "y,delta,band_hz,level_db,kurze_anderson_db\n");
  Bands prev(0.f);
  bool first = true;
  for (int i = 0; i <= 500; ++i) {
    const float y = 2.f - 0.012f * float(i);
    const glm::vec3 lis{5.f, y, 0.f};
    // Path difference; negative on the lit side (listener sees the source over the edge).
    const float over = glm::length(src) + glm::length(lis) - glm::length(lis - src);
    const bool shadow = y < 1.f;  // the shadow boundary at x = 5 is y = +1
    const double delta = shadow ? double(over) : -double(over);
    const Bands lv = s.levels(src, lis);
    for (int b = 1; b <= 6; ++b) {
      const double n = 2 * delta * bandCentreExactHz(b) / kC;
      std::fprintf(f, "%.4f,%.5f,%.0f,%.3f,%.3f\n", double(y), delta, bandCentreExactHz(b),
                   double(lv[b]), n > 0 ? -kurzeAnderson(n) : std::nan(""));
      if (!first) CHECK(std::abs(lv[b] - prev[b]) < 1.0);  // 12 mm steps
    }
    prev = lv;
    first = false;
  }
  std::fclose(f);
}

TEST_CASE("Diffraction: the shipped walk past a partition's edge (scenes/shoebox-corner.json)",
          "[diffraction]") {
  const SceneDesc scene = loadScene(std::string(DPC_SOURCE_DIR) + "/scenes/shoebox-corner.json");
  Geometry geometry(scene.mesh, scene.materials, 0.5f);
  EmbreeTracer tracer(scene.mesh);
  const EdgeDiffraction diffraction(scene.mesh);
  // The room's 12 edges (inner corners, never diffracting from inside) and the partition's
  // free vertical edge; its rims on the floor, ceiling and wall are sealed.
  REQUIRE(diffraction.edges().size() == 13);
  PropagationSettings ps = scene.propagation;
  Propagator prop(geometry, tracer, ps);
  const glm::vec3 src = scene.sources[0].position;
  Bands prev(0.f);
  double maxStep = 0.0;
  for (int i = 0; i <= 500; ++i) {
    const glm::vec3 lis{8.f, 1.6f, 1.5f + 0.01f * float(i)};
    const ListenerSphere l{lis, scene.listeners[0].radius};
    DirectSound d = prop.directSound(src, l);
    const bool visible = d.visible;
    diffraction.apply(tracer, src, l, ps.speedOfSound, prop.airAttenuationPerMetre(), d);
    REQUIRE(d.visible);  // in the partition's shadow the edge path still arrives
    const double lv = 10 * std::log10(double(d.intensity[4]));
    if (i % 50 == 0)
      std::printf("corner walk: z %.2f direct %s, 1 kHz level %.2f dB re 1/m^2\n", double(lis.z),
                  visible ? "visible" : "occluded", lv);
    if (i > 0) maxStep = std::max(maxStep, std::abs(lv - double(prev[4])));
    prev[4] = float(lv);
  }
  std::printf("corner walk: largest step per 1 cm %.3f dB\n", maxStep);
  CHECK(maxStep < 1.0);
}

TEST_CASE("Diffraction: wedges of 240-330 degrees against the exact Biot-Tolstoy-Medwin result",
          "[diffraction]") {
  // Point source 3 m from the edge, listener 2 m from it and 0.5 m higher (a skewed path), in
  // the shadow zone (only the diffracted field) and in the lit zone past the reflection
  // boundary (direct + diffracted, summed coherently). Reference: the exact BTM transfer
  // function; dpc: UTD (asymptotic in kL), |p|^2 averaged over the same 16 frequencies per
  // band. UTD evaluated with exact Fresnel integrals differs from BTM by at most 0.05 dB in
  // these geometries at 250 Hz (kL >= 6) and less above (computed independently, in double
  // precision); the tolerance of 0.2 dB adds the solid's far edges (each path about -35 dB re
  // the near edge's, summed coherently: up to +-0.15 dB) and single-precision geometry.
  const double deg = std::numbers::pi / 180;
  struct Case {
    double open, thS, thR;
    bool lit;
  };
  const Case cases[] = {{240 * deg, 20 * deg, 215 * deg, false}, {270 * deg, 30 * deg, 240 * deg, false},
                        {300 * deg, 40 * deg, 260 * deg, false}, {330 * deg, 45 * deg, 300 * deg, false},
                        {270 * deg, 40 * deg, 180 * deg, true},  {300 * deg, 60 * deg, 150 * deg, true}};
  const double rS = 3, rR = 2, dz = 0.5;
  double worst = 0.0;
  for (const Case& k : cases) {
    Setup s(solidWedge(k.open));
    const glm::vec3 src{float(rS * std::cos(k.thS)), float(rS * std::sin(k.thS)), 0.f};
    const glm::vec3 lis{float(rR * std::cos(k.thR)), float(rR * std::sin(k.thR)), float(dz)};
    const float dist = glm::length(lis - src);
    REQUIRE(s.tracer.occluded(TraceRay{src, (lis - src) / dist, 1e-3f, dist - 1e-3f}) == !k.lit);
    const Bands level = s.levels(src, lis);  // dB re the free field at dist
    for (int b = 2; b <= 6; ++b) {           // 250 Hz - 4 kHz
      std::vector<double> freqs;
      for (int i = 0; i < kDiffractionFrequenciesPerBand; ++i)
        freqs.push_back(diffractionFrequencyHz(b, i));
      const auto h = btmTransfer(k.open, rS, k.thS, rR, k.thR, dz, freqs);
      double mean = 0.0;
      for (size_t i = 0; i < freqs.size(); ++i) {
        std::complex<double> p = h[i];
        if (k.lit) p += std::polar(1.0 / dist, -2 * std::numbers::pi * freqs[i] * dist / kC);
        mean += std::norm(p) / double(freqs.size());
      }
      const double ref = 10 * std::log10(mean * double(dist) * double(dist));
      const double diff = double(level[b]) - ref;
      std::printf("wedge %3.0f deg %-6s %5.0f Hz: dpc %7.2f dB, BTM %7.2f dB, %+.3f\n",
                  k.open / deg, k.lit ? "lit" : "shadow", bandCentreExactHz(b),
                  double(level[b]), ref, diff);
      worst = std::max(worst, std::abs(diff));
      CHECK(std::abs(diff) < 0.2);
    }
  }
  std::printf("wedges vs BTM: largest difference %.3f dB\n", worst);
}

TEST_CASE("Diffraction: apply reports the edges whose paths it counted", "[diffraction]") {
  Setup s(screen());
  const glm::vec3 src{-5.f, -1.f, 0.f}, lis{5.f, -1.f, 0.f};  // behind the screen's top edge
  DirectSound blocked;  // the screen hides the source: not visible, no intensity
  blocked.distance = glm::length(lis - src);
  blocked.delaySeconds = blocked.distance / kC;
  blocked.direction = glm::normalize(src - lis);
  DirectSound d = blocked;
  std::vector<uint32_t> used = {99};  // cleared by apply
  const size_t n = s.diffraction.apply(s.tracer, src, ListenerSphere{lis, 0.01f}, kC, Bands(0.f),
                                       d, {}, glm::vec3(1.f, 0.f, 0.f), &used);
  // The screen's four rim edges (top y = 0, bottom y = -500, sides z = +-500): each has its
  // Fermat point inside it and both legs free; each reported once, the count apply returns.
  REQUIRE(s.diffraction.edges().size() == 4);
  REQUIRE(n == 4);
  REQUIRE(used.size() == 4);
  std::vector<uint32_t> sorted = used;
  std::sort(sorted.begin(), sorted.end());
  CHECK(sorted == std::vector<uint32_t>{0, 1, 2, 3});
  // The shortest path is over the top edge, sqrt(5^2 + 1^2) on either side: the direct sound.
  CHECK(d.distance == Approx(2.0 * std::sqrt(26.0)).epsilon(1e-6));
  // The same pair without the list counts the same.
  DirectSound d2 = blocked;
  CHECK(s.diffraction.apply(s.tracer, src, ListenerSphere{lis, 0.01f}, kC, Bands(0.f), d2) == 4);
}
