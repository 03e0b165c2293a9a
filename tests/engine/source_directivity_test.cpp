// Source directivity in the engine (scene/directivity.h): the direct sound, the rays and the
// exact specular paths weighted by the pattern at their leaving direction, the source's power
// unchanged, and the source's rotation turning the result.
#include <catch2/catch.hpp>
#include <cmath>
#include <fstream>
#include <string>
#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>
#include <vector>

#include "engine/simulation.h"
#include "scene/directivity.h"
#include "scene/orientation.h"
#include "testing/test_scenes.h"
#include "testing/test_util.h"

using namespace dpc;

namespace {

constexpr float kPi = 3.14159265f;
const glm::vec3 kCentre{100, 100, 100};

double db(double x) {
  return 10.0 * std::log10(x);
}

/// A 200 m absorbing box (anechoic within order 0) with a source at its centre.
SceneDesc anechoic(const Directivity& d, glm::quat rotation = glm::quat(1, 0, 0, 0)) {
  SceneDesc s = test::makeShoebox({200, 200, 200}, Bands(1.f), 1.f, kCentre, kCentre + 4.f, 0.5f);
  s.sources[0].directivity = d;
  s.sources[0].rotation = rotation;
  return s;
}

/// Listeners 4 m from the centre in the x-z plane at the angles (degrees) from +x toward +z.
std::vector<ListenerSphere> ring(const std::vector<float>& degrees) {
  std::vector<ListenerSphere> l;
  for (float deg : degrees) {
    const float t = deg * kPi / 180.f;
    l.push_back({kCentre + 4.f * glm::vec3(std::cos(t), 0.f, std::sin(t)), 0.5f});
  }
  return l;
}

/// The direct sound's 1 kHz intensity at each listener of `listeners`.
std::vector<double> directAt(const SceneDesc& scene, const std::vector<ListenerSphere>& listeners) {
  PropagationSettings ps = scene.propagation;
  ps.raysPerFrame = 1;
  ps.maxOrder = 0;
  Simulation sim(scene, ps);
  sim.runFrame(listeners, {scene.sources[0].position});
  std::vector<double> out;
  for (size_t l = 0; l < listeners.size(); ++l) out.push_back(sim.result(0, l).direct.intensity[4]);
  return out;
}

}  // namespace

// Oracle: the pattern's energy gain ((1 - a) + a cos theta)^2 (Eargle, The Microphone Book,
// ch. 5). The direct sound is analytic, so the level follows it to float rounding; 0.5 dB is
// the tolerance.
TEST_CASE("The direct sound's level versus angle follows the pattern", "[directivity]") {
  std::vector<float> angles;
  for (int deg = 0; deg <= 180; deg += 15) angles.push_back(float(deg));
  const auto listeners = ring(angles);
  for (const auto& pattern : kDirectivityPatterns) {
    INFO(pattern.name);
    const auto level = directAt(anechoic(Directivity{Bands(pattern.a)}), listeners);
    for (size_t i = 0; i < angles.size(); ++i) {
      const float g = directivityGain(pattern.a, std::cos(angles[i] * kPi / 180.f));
      INFO(angles[i] << " degrees");
      if (g > 1e-2f)
        CHECK(std::abs(db(level[i] / level[0]) - db(g)) < 0.5);
      else
        CHECK(db(level[i] / level[0]) < -20.0);
    }
  }
  const auto cardioid = directAt(anechoic(Directivity{Bands(0.5f)}), listeners);
  CHECK(std::abs(db(cardioid[6] / cardioid[0]) + 6.02) < 0.5);  // 90 degrees: -6 dB
  CHECK(db(cardioid[12] / cardioid[0]) <= -20.0);               // rear
  // Same power as omni: on axis 10 lg Q = 10 lg 3 = +4.77 dB above the omni source.
  const auto omni = directAt(anechoic(Directivity{}), listeners);
  CHECK(std::abs(db(cardioid[0] / omni[0]) - 4.771) < 0.01);
}

// The rays carry the pattern too: order-0 rays through each sphere estimate the direct sound
// (propagation_test's calibration). With N rays a sphere 4 m away is hit by p N of them, p =
// 0.39 %, relative sigma = sqrt((1 - p) / (N p)) = 1.1 % (0.05 dB) on axis and at most 2.3 %
// where the pattern is above -15 dB re on axis; the sphere averages the pattern over its
// 7 degree cap, which adds under 0.3 dB there and lifts a null (rear of a cardioid, sides of a
// figure of eight) to about -25 dB. So: within 0.5 dB of the pattern above -15 dB, below
// -12 dB elsewhere. Writes build/directivity_polar.csv for scripts/plot_directivity.py.
TEST_CASE("Emitted rays are weighted by the pattern (writes directivity_polar.csv)",
          "[directivity][heavy]") {
  std::vector<float> angles;
  for (int deg = 0; deg <= 180; deg += 15) angles.push_back(float(deg));
  const auto listeners = ring(angles);
  std::ofstream csv(std::string(DPC_BINARY_DIR) + "/directivity_polar.csv");
  csv << "pattern,a,angle_deg,rays_db,direct_db,pattern_db\n";
  for (const char* name : {"subcardioid", "cardioid", "hypercardioid", "figure8"}) {
    const float a = *directivityPatternA(name);
    const SceneDesc scene = anechoic(Directivity{Bands(a)});
    PropagationSettings ps;
    ps.raysPerFrame = 2000000;
    ps.maxOrder = 0;
    ps.estimator = Estimator::kPathTracing;
    Simulation sim(scene, ps);
    FrameInputs in = Simulation::inputsAt(listeners, {scene.sources[0].position});
    in.includeDirectRays = true;
    sim.runFrame(in);
    // The omni source's direct sound at 4 m: the reference of every level (same power).
    const double omni = directAt(anechoic(Directivity{}), ring({0.f}))[0];
    const double onAxis = sim.result(0, 0).energy.total()[4];
    for (size_t l = 0; l < angles.size(); ++l) {
      const double rays = sim.result(0, l).energy.total()[4];
      const float c = std::cos(angles[l] * kPi / 180.f);
      const double pattern = db(directivityGain(a, c) / directivityMeanGain(a));
      csv << name << "," << a << "," << angles[l] << "," << db(rays / omni) << ","
          << db(sim.result(0, l).direct.intensity[4] / omni) << "," << pattern << "\n";
      INFO(name << " at " << angles[l] << " degrees: rays " << db(rays / omni) << " dB, pattern "
                << pattern << " dB re omni");
      if (db(directivityGain(a, c)) > -15.0)
        CHECK(std::abs(db(rays / omni) - pattern) < 0.5);
      else
        CHECK(db(rays / onAxis) < -12.0);
    }
  }
}

// Room acoustics: the reverberant field is fed by the source's power in all directions, so a
// directional source of the same power gives the omni source's reverberant level (the
// direct-to-reverberant ratio rises by the directivity index; Kuttruff, Room Acoustics, 5th
// ed., ch. 5, the reverberation distance). Shoebox with scattering 1, mean free path 4V/S =
// 3.5 m: the energy after 100 ms (about ten reflections; before 50 ms the forward-facing
// source still puts more energy on the listener's side: +5 % at 40 ms); each frame's rays are
// new, and the same seed makes omni and cardioid trace the same rays, so the per-frame ratio's
// spread is the Monte Carlo error of the weighting. The mean ratio must be 1 within 4 standard
// errors of the frames and 1 %, the room's remaining memory of the emission direction.
TEST_CASE("A directional source's reverberant energy equals the omni source's",
          "[directivity][statistics]") {
  const size_t lateBin = 100;  // 1 ms bins
  auto run = [](const Directivity& d, int frames) {
    SceneDesc s = test::makeShoebox({10, 3, 7}, Bands(0.2f), 1.f, {5, 1.5f, 3.5f}, {7, 1.6f, 5});
    s.sources[0].directivity = d;
    PropagationSettings ps = s.propagation;
    ps.raysPerFrame = 20000;
    ps.estimator = Estimator::kPathTracing;
    Simulation sim(s, ps);
    std::vector<double> late;
    std::vector<double> direct;
    for (int f = 0; f < frames; ++f) {
      sim.runFrame(s.listeners[0].position);
      const auto& bins = sim.result(0).energy.bins();
      double e = 0;
      for (size_t b = lateBin; b < bins.size(); ++b) e += bins[b][4];
      late.push_back(e);
      direct.push_back(sim.result(0).direct.intensity[4]);
    }
    return std::pair(late, direct);
  };
  const int frames = 16;
  const auto [omniLate, omniDirect] = run(Directivity{}, frames);
  const auto [cardLate, cardDirect] = run(Directivity{Bands(0.5f)}, frames);
  std::vector<double> ratio;
  for (int f = 0; f < frames; ++f) ratio.push_back(cardLate[size_t(f)] / omniLate[size_t(f)]);
  const auto [mean, se] = test::meanAndStandardError(ratio);
  INFO("reverberant ratio cardioid / omni " << mean << " +- " << se);
  CHECK(std::abs(mean - 1.0) < 4 * se + 0.01);
  // The direct sound: the cardioid's weight toward the listener exactly.
  const glm::vec3 toListener = glm::normalize(glm::vec3(2, 0.1f, 1.5f));
  CHECK(cardDirect[0] / omniDirect[0] ==
        Approx(directivityWeight(Directivity{Bands(0.5f)}, toListener.x)[4]).epsilon(1e-5));
}

// A quarter turn about +y takes the forward axis from +x to -z: the levels measured on a ring
// turn with it, whether the rotation comes from the scene or from FrameInputs::sourceRotations.
TEST_CASE("Rotating the source rotates the result", "[directivity]") {
  const Directivity cardioid{Bands(0.5f)};
  const glm::quat quarter = glm::angleAxis(kPi / 2, glm::vec3(0, 1, 0));
  const auto listeners = ring({0.f, 90.f, 180.f, 270.f});
  const auto plain = directAt(anechoic(cardioid), listeners);
  const auto turned = directAt(anechoic(cardioid, quarter), listeners);
  // Ring angle 270 degrees is -z: the turned source's on-axis direction.
  CHECK(turned[3] == Approx(plain[0]).epsilon(1e-5));
  CHECK(turned[1] == Approx(plain[2]).margin(1e-12));  // +z: the turned source's rear
  CHECK(turned[0] == Approx(plain[1]).epsilon(1e-5));  // +x: its side
  // The same turn at run time.
  const SceneDesc scene = anechoic(cardioid);
  PropagationSettings ps;
  ps.raysPerFrame = 1;
  ps.maxOrder = 0;
  Simulation sim(scene, ps);
  FrameInputs in = Simulation::inputsAt(listeners, {scene.sources[0].position});
  in.sourceRotations = {quarter};
  sim.runFrame(in);
  CHECK(sim.result(0, 3).direct.intensity[4] == Approx(plain[0]).epsilon(1e-5));
}

// Exact specular paths leave the source toward their first reflection point P1: each path's
// intensity is the omni path's times the pattern's weight in that direction (float rounding).
TEST_CASE("Exact specular paths are weighted toward their first reflection point",
          "[directivity]") {
  auto paths = [](const Directivity& d) {
    SceneDesc s = test::makeShoebox({10, 3, 7}, Bands(0.2f), 0.f, {2, 1.5f, 2}, {7, 1.6f, 5});
    s.sources[0].directivity = d;
    s.sources[0].rotation = glm::angleAxis(0.3f, glm::normalize(glm::vec3(1, 2, 3)));
    PropagationSettings ps = s.propagation;
    ps.raysPerFrame = 4096;
    ps.exactOrder = 2;
    Simulation sim(s, ps);
    sim.runFrame(s.listeners[0].position);
    return std::pair(sim.specularPaths(0), sourceForward(s.sources[0].rotation));
  };
  const Directivity hyper{Bands(0.75f)};
  const auto [omni, forward] = paths(Directivity{});
  const std::vector<SpecularPath> directional = paths(hyper).first;
  REQUIRE(omni.size() >= 20);  // 6 first-order and most second-order image sources
  REQUIRE(directional.size() == omni.size());
  for (size_t i = 0; i < omni.size(); ++i) {
    REQUIRE(directional[i].key == omni[i].key);
    const glm::vec3 leaving = glm::normalize(omni[i].points[0] - glm::vec3(2, 1.5f, 2));
    const float c = glm::dot(forward, leaving);
    const double expected = (0.25 + 0.75 * c) * (0.25 + 0.75 * c) / (0.0625 + 0.1875);
    CHECK(directional[i].intensity[4] / omni[i].intensity[4] == Approx(expected).epsilon(1e-4));
  }
}

// Edge diffraction leaves the source toward the edge point Q: behind a screen (no line of
// sight) the diffracted sound is the omni source's times the weight toward Q, not toward the
// listener. Source at the box centre facing +x, screen at x + 2 m up to 1.5 m above it, its
// other edges on the box's walls 100 m away; listener 4 m along +x. Q = (2, 1.5, 0) from the
// source: cos = 0.8, cardioid weight 3 * 0.9^2 = 2.43 (toward the listener it would be 3).
// Tolerance 1 %: the far edges' paths are 1e-4 of the top edge's.
TEST_CASE("Diffracted direct sound is weighted toward its edge point", "[directivity]") {
  auto behindScreen = [](const Directivity& d) {
    SceneDesc s = anechoic(d);
    test::addPanel(s.mesh, {102, 0, 0}, {0, 0, 200}, {0, 101.5f, 0}, 0);
    PropagationSettings ps;
    ps.raysPerFrame = 1;
    ps.maxOrder = 0;
    Simulation sim(s, ps);
    sim.runFrame(ring({0.f}), {s.sources[0].position});
    REQUIRE(sim.result(0).direct.visible);  // through the diffracted path
    return sim.result(0).direct.intensity;
  };
  const Bands omni = behindScreen(Directivity{});
  const Bands cardioid = behindScreen(Directivity{Bands(0.5f)});
  for (int b = 0; b < kNumBands; ++b) CHECK(cardioid[b] / omni[b] == Approx(2.43).epsilon(0.01));
}
