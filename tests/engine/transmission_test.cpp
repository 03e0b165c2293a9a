// Sound transmission through surfaces (engine/transmission.h): the Monte Carlo choice's energy
// balance, a thin panel in free field (the direct sound and the rays), and the room-to-room
// level difference of EN ISO 12354-1 across a partition between two diffuse rooms.
#include <array>
#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

#include "engine/embree_tracer.h"
#include "engine/geometry.h"
#include "engine/propagation.h"
#include "engine/transmission.h"
#include "scene/transmission.h"
#include "testing/test_util.h"
#include "testing/test_scenes.h"

using namespace dpc;

namespace {

double db(double x) {
  return 10.0 * std::log10(x);
}

/// A 200 m fully absorbing box (free field for every ray) with a source at `source`, one
/// listener at `listener`, and, when R is finite, a 6 x 6 m double-sided panel of transmission
/// loss R (absorption alphaPanel) in the plane x = 100 between them.
SceneDesc freeField(float lossDb, float alphaPanel, glm::vec3 source, glm::vec3 listener) {
  SceneDesc s = test::makeShoebox({200, 200, 200}, Bands(1.f), 1.f, source, listener, 0.5f);
  Material panel{"panel", Bands(alphaPanel), Bands(0.f)};
  panel.transmissionLossDb = Bands(lossDb);
  s.materials.push_back(panel);
  if (std::isfinite(lossDb))
    test::addPanel(s.mesh, {100, 97, 97}, {0, 6, 0}, {0, 0, 6}, 1);
  s.propagation.airAbsorption = false;
  return s;
}

/// Band energies (1/m^2, summed hit intensities over N rays) at each listener, of `frames`
/// frames of `rays` rays; direct rays counted when `direct`.
std::vector<Bands> rayEnergy(const SceneDesc& scene, const std::vector<ListenerSphere>& listeners,
                             int rays, int frames, bool direct) {
  PropagationSettings ps = scene.propagation;
  ps.raysPerFrame = rays;
  ps.threads = 2;
  Geometry geometry(scene.mesh, scene.materials, ps.patchSize, scene.objects);
  EmbreeTracer tracer(scene.mesh, scene.objects);
  Propagator prop(geometry, tracer, ps);
  std::vector<FrameGroups> groups(listeners.size());
  std::vector<FrameGroups*> pointers;
  for (FrameGroups& g : groups) pointers.push_back(&g);
  std::vector<Bands> energy(listeners.size(), Bands(0.f));
  for (int f = 0; f < frames; ++f) {
    for (FrameGroups& g : groups) g.clear();
    TraceRequest rq = test::traceRequest(ps, uint64_t(f), 0, scene.sources[0].position, listeners);
    rq.includeDirectRays = direct;
    prop.traceFrame(rq, pointers);
    for (size_t l = 0; l < listeners.size(); ++l)
      for (const FrameGroups::Group& g : groups[l].groups())
        energy[l] += g.intensity * (1.f / float(rays * frames));
  }
  return energy;
}

}  // namespace

// Oracle: conservation at one surface. Integrating the choice over u on a uniform grid of n
// points gives its expectation up to the grid's quadrature error, at most one grid step's share
// of the larger branch weight: 1/n * max(tau/p, (1-alpha)/(1-p)) <= 10/n.
TEST_CASE("Energy balance at a transmitting surface, in expectation", "[transmission]") {
  const Bands alpha{0.3f};
  Bands loss;
  for (int b = 0; b < kNumBands; ++b) loss[b] = 6.f + 4.f * float(b);  // tau 0.25 .. 1.6e-3
  const Bands tau = transmittanceOf(loss);
  const Bands reflectance = Bands(1.f) - alpha;
  constexpr int n = 100000;
  // Summed in double: a float sum of n terms would add its own rounding (n * 2^-24).
  std::array<double, kNumBands> reflected{}, transmitted{};
  for (int i = 0; i < n; ++i) {
    Bands e(1.f);
    const bool through = chooseTransmission(reflectance, tau, (float(i) + 0.5f) / n, e);
    for (int b = 0; b < kNumBands; ++b) (through ? transmitted : reflected)[size_t(b)] += e[b];
  }
  for (int b = 0; b < kNumBands; ++b) {
    INFO("band " << b);
    const double t = transmitted[size_t(b)] / n, r = reflected[size_t(b)] / n;
    CHECK(std::abs(t - tau[b]) <= 10.0 / n);
    CHECK(std::abs(r - reflectance[b]) <= 10.0 / n);
    const double dissipated = double(alpha[b]) - tau[b];
    CHECK(dissipated >= 0.0);
    CHECK(std::abs(r + t + dissipated - 1.0) <= 20.0 / n);
  }
  CHECK(transmissionProbability(Bands(1.f), reflectance, tau) >= kMinTransmissionProbability);
  CHECK(transmissionProbability(Bands(1.f), reflectance, Bands(0.f)) == 0.f);
}

// Oracle: the direct path through a panel carries exactly tau = 10^(-R/10) (float rounding of
// the product: 1e-3 dB).
TEST_CASE("A thin panel in free field attenuates the direct sound by R", "[transmission]") {
  const glm::vec3 src{96, 100, 100}, lis{104, 100, 100};
  for (float r : {10.f, 20.f, 35.f}) {
    const SceneDesc open = freeField(kOpaqueTransmissionLossDb, 1.f, src, lis);
    const SceneDesc panel = freeField(r, 1.f, src, lis);
    const ListenerSphere l{lis, 0.5f};
    Geometry g0(open.mesh, open.materials, 0.5f), g1(panel.mesh, panel.materials, 0.5f);
    EmbreeTracer t0(open.mesh), t1(panel.mesh);
    Propagator p0(g0, t0, open.propagation), p1(g1, t1, panel.propagation);
    const DirectSound d0 = p0.directSound(src, l), d1 = p1.directSound(src, l);
    REQUIRE(d1.visible);
    CHECK(d1.crossings == 1);
    CHECK_FALSE(d1.lineOfSight());
    for (int b = 0; b < kNumBands; ++b)
      CHECK(std::abs(db(d0.intensity[b] / d1.intensity[b]) - r) < 1e-3);
  }
  // Opaque: blocked as without transmission.
  const SceneDesc opaque = freeField(kOpaqueTransmissionLossDb, 1.f, src, lis);
  SceneDesc wall = opaque;
  test::addPanel(wall.mesh, {100, 97, 97}, {0, 6, 0}, {0, 0, 6}, 0);
  Geometry g(wall.mesh, wall.materials, 0.5f);
  EmbreeTracer t(wall.mesh);
  CHECK_FALSE(Propagator(g, t, wall.propagation).directSound(src, {lis, 0.5f}).visible);
}

// Oracle: rays through the panel carry tau of the free-field energy in expectation. The panel
// absorbs half (alpha 0.5) so the choice is random (p = 0.3 for R = 20 dB): the estimate's
// relative standard deviation is sqrt((1 - p) / (p n)) for n listener hits of the free field;
// n ~ N R_l^2 / (4 d^2) = 400k * 0.25 / 64 = 1560, so 0.039; the tolerance is 4 standard
// deviations, 0.155 relative (0.63 dB), plus the free field's own 4 sigma, 0.1 (0.41 dB).
TEST_CASE("Rays through a thin panel carry its transmittance", "[transmission]") {
  const glm::vec3 src{96, 100, 100}, lis{104, 100, 100};
  const std::vector<ListenerSphere> l{{lis, 0.5f}};
  const float r = 20.f;
  const SceneDesc open = freeField(kOpaqueTransmissionLossDb, 0.5f, src, lis);
  const auto free = rayEnergy(open, l, 100000, 4, true);
  const auto through = rayEnergy(freeField(r, 0.5f, src, lis), l, 100000, 4, true);
  for (int b = 0; b < kNumBands; ++b) {
    INFO("band " << b);
    CHECK(std::abs(db(free[0][b] / through[0][b]) - r) < 1.04);
  }
}

// Oracle: EN ISO 12354-1 (and Kuttruff, Room Acoustics, ch. 10): between two diffuse rooms
// joined only by a partition of area S, the level difference is D = R - 10 lg(S / A2), A2 the
// receiving room's equivalent absorption area (Sabine: sum of S_i alpha_i, the partition's
// alpha counting its transmission). Two 5 x 3 x 4 m rooms, every surface alpha = 0.2 and
// fully scattering (a diffuse field), S = 12 m^2, A2 = 0.2 * 94 m^2. The source stands in the
// far corner of room 1, so the partition is lit by the diffuse field rather than by the direct
// sound (a source 1 m from the partition lowers D by 1.3 dB). The levels are the mean
// reverberant energies of four listener spheres per room; the tolerance is the issue's 1.5 dB
// per band (measured: D is 0.2 dB above the formula for R = 20, 30, 40 dB at seed 1).
TEST_CASE("Room-to-room level difference follows EN 12354-1", "[transmission][statistics]") {
  const std::vector<ListenerSphere> listeners{
      {{1.5f, 1.5f, 1.0f}, 0.5f}, {{3.5f, 1.0f, 1.0f}, 0.5f}, {{3.0f, 2.0f, 3.0f}, 0.5f},
      {{2.5f, 2.2f, 2.0f}, 0.5f}, {{6.5f, 1.5f, 1.5f}, 0.5f}, {{8.5f, 1.0f, 3.0f}, 0.5f},
      {{7.5f, 2.0f, 2.5f}, 0.5f}, {{8.8f, 1.8f, 1.0f}, 0.5f}};
  for (float r : {20.f, 30.f, 40.f}) {
    SceneDesc s = test::makeShoebox({10, 3, 4}, Bands(0.2f), 1.f, {0.8f, 1.0f, 3.3f},
                                    listeners[0].position);
    Material partition{"partition", Bands(0.2f), Bands(1.f)};
    partition.transmissionLossDb = Bands(r);
    s.materials.push_back(partition);
    test::addPanel(s.mesh, {5, 0, 0}, {0, 0, 4}, {0, 3, 0}, 1);
    s.propagation.airAbsorption = false;
    s.propagation.maxOrder = 400;
    const auto e = rayEnergy(s, listeners, 20000, 4, false);
    Bands e1(0.f), e2(0.f);
    for (size_t l = 0; l < 4; ++l) {
      e1 += e[l];
      e2 += e[l + 4];
    }
    const double expected = double(r) - db(12.0 / (0.2 * 94.0));
    for (int b = 0; b < kNumBands; ++b) {
      INFO("R " << r << " band " << b << " D " << db(e1[b] / e2[b]) << " expected " << expected);
      CHECK(std::abs(db(e1[b] / e2[b]) - expected) < 1.5);
    }
  }
}

// Oracle: as for the static panel, exactly R on the direct path (1e-3 dB), now with the panel a
// moving object: between source and listener it attenuates by R; moved aside it does not.
TEST_CASE("A moving panel attenuates the direct sound by R where it stands", "[transmission]") {
  const glm::vec3 src{96, 100, 100}, lis{104, 100, 100};
  const float r = 25.f;
  SceneDesc s = freeField(kOpaqueTransmissionLossDb, 1.f, src, lis);
  s.materials[1].transmissionLossDb = Bands(r);
  ObjectDesc panel;
  panel.name = "panel";
  test::addPanel(panel.mesh, {0, -3, -3}, {0, 6, 0}, {0, 0, 6}, 1);
  ObjectKeyframe between;
  between.position = {100, 100, 100};
  panel.trajectory = {between};
  s.objects.push_back(panel);
  Geometry geometry(s.mesh, s.materials, 0.5f, s.objects);
  EmbreeTracer tracer(s.mesh, s.objects);
  Propagator prop(geometry, tracer, s.propagation);
  const ListenerSphere l{lis, 0.5f};
  const DirectSound through = prop.directSound(src, l);
  tracer.setObjectPose(0, Pose{{100, 150, 100}, glm::quat(1, 0, 0, 0)});
  tracer.commitPoses();
  const DirectSound aside = prop.directSound(src, l);
  CHECK(through.crossings == 1);
  CHECK(aside.crossings == 0);
  CHECK(aside.lineOfSight());
  for (int b = 0; b < kNumBands; ++b)
    CHECK(std::abs(db(aside.intensity[b] / through.intensity[b]) - r) < 1e-3);
}
