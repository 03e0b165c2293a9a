// Reciprocity of the two tracing directions (PropagationSettings::tracing): rays from the
// sources and rays from the listeners estimate the same energy response, per source, per
// arrival direction and with directional sources, and find the same exact specular paths.
//
// Oracle: the other direction, run with independent random streams. Each frame of plain path
// tracing is an independent estimate, so the per-frame energies in a time window have a sample
// mean and a standard error; two estimators of the same expectation differ by at most
// kSigmas combined standard errors except with probability below 1e-4 per comparison
// (Gaussian tail at 4 sigma: 6e-5; the window sums over thousands of hits, so their mean is
// close to normal). A wrong factor (the source sphere's area, a directivity weight toward the
// wrong direction, an exact path's hits kept or dropped twice) shows as several sigmas.
#include <catch2/catch.hpp>
#include <cmath>
#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>
#include <string>
#include <vector>

#include "engine/simulation.h"
#include "testing/test_scenes.h"

using namespace dpc;

namespace {

constexpr double kSigmas = 4.0;
constexpr int kFrames = 40;
constexpr size_t kBand = 4;  ///< 1 kHz
/// Time windows, seconds: early reflections, early decay, late decay.
const std::vector<std::pair<double, double>> kWindows = {{0.0, 0.03}, {0.03, 0.1}, {0.1, 0.6}};

struct Stat {
  double sum = 0.0, sum2 = 0.0;
  int n = 0;
  void add(double x) {
    sum += x;
    sum2 += x * x;
    ++n;
  }
  double mean() const { return sum / n; }
  double sem() const {
    const double m = mean();
    return std::sqrt(std::max(0.0, sum2 / n - m * m) / (n - 1));
  }
};

double windowEnergy(const EnergyResponse& e, double t0, double t1) {
  double sum = 0.0;
  for (size_t b = 0; b < e.binCount(); ++b) {
    const double t = (double(b) + 0.5) * e.binSeconds();
    if (t >= t0 && t < t1) sum += e.bins()[b][kBand];
  }
  return sum;
}

/// Per source, per window (and per axis when `axes`), the statistics of kFrames frames.
struct Run {
  std::vector<std::vector<Stat>> windows;  ///< [source][window]
  std::vector<std::vector<Stat>> axes;     ///< [source][axis], 0..0.6 s
  std::vector<size_t> specularPaths;       ///< per source, last frame
};

Run run(const SceneDesc& scene, Tracing tracing, uint64_t seed, bool axes = false) {
  PropagationSettings ps = scene.propagation;
  ps.estimator = Estimator::kPathTracing;
  ps.tracing = tracing;
  ps.seed = seed;
  ps.irLength = 0.6f;
  Simulation sim(scene, ps);
  const std::vector<glm::vec3> axisDirs = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0},
                                           {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  if (axes) sim.enableDirectional(axisDirs);
  std::vector<glm::vec3> sources;
  for (const SourceDesc& s : scene.sources) sources.push_back(s.position);
  const ListenerSphere listener{scene.listeners[0].position, scene.listeners[0].radius};
  Run r;
  r.windows.assign(sources.size(), std::vector<Stat>(kWindows.size()));
  r.axes.assign(sources.size(), std::vector<Stat>(axisDirs.size()));
  for (int f = 0; f < kFrames + 2; ++f) {
    sim.runFrame(std::span(&listener, 1), sources);
    if (f < 2) continue;  // the exact paths' sequences are found in the first frames
    for (size_t s = 0; s < sources.size(); ++s) {
      for (size_t w = 0; w < kWindows.size(); ++w)
        r.windows[s][w].add(
            windowEnergy(sim.result(s).energy, kWindows[w].first, kWindows[w].second));
      if (axes)
        for (size_t k = 0; k < axisDirs.size(); ++k)
          r.axes[s][k].add(windowEnergy(sim.directional(s).response(k), 0.0, 0.6));
    }
  }
  for (size_t s = 0; s < sources.size(); ++s) r.specularPaths.push_back(sim.specularPaths(s).size());
  return r;
}

void requireAgree(const Stat& a, const Stat& b, const std::string& what) {
  const double sigma = std::sqrt(a.sem() * a.sem() + b.sem() * b.sem());
  INFO(what << ": from sources " << a.mean() << " +- " << a.sem() << ", from listeners "
            << b.mean() << " +- " << b.sem() << " (" << (a.mean() - b.mean()) / sigma
            << " sigma)");
  REQUIRE(a.mean() > 0.0);
  CHECK(std::abs(a.mean() - b.mean()) <= kSigmas * sigma);
}

void requireReciprocal(const SceneDesc& scene, bool axes = false) {
  const Run forward = run(scene, Tracing::kFromSources, 11, axes);
  const Run backward = run(scene, Tracing::kFromListeners, 12, axes);
  for (size_t s = 0; s < scene.sources.size(); ++s) {
    CHECK(forward.specularPaths[s] == backward.specularPaths[s]);
    for (size_t w = 0; w < kWindows.size(); ++w)
      requireAgree(forward.windows[s][w], backward.windows[s][w],
                   "source " + std::to_string(s) + " window " + std::to_string(w));
    if (axes)
      for (size_t k = 0; k < forward.axes[s].size(); ++k)
        requireAgree(forward.axes[s][k], backward.axes[s][k],
                     "source " + std::to_string(s) + " axis " + std::to_string(k));
  }
}

/// 10 x 7 x 3 m, absorption 0.2, scattering 0.3 (specular and diffuse paths both matter).
SceneDesc room() {
  return test::makeShoebox({10, 7, 3}, Bands(0.2f), 0.3f, {2.5f, 2.f, 1.5f}, {7.f, 4.5f, 1.6f});
}

}  // namespace

TEST_CASE("Rays from the listener give the energy response of rays from the source",
          "[engine][statistics]") {
  requireReciprocal(room());
}

TEST_CASE("Reciprocal tracing keeps each arrival direction", "[engine][statistics]") {
  requireReciprocal(room(), true);
}

TEST_CASE("Reciprocal tracing weights a directional source toward its leaving direction",
          "[engine][statistics]") {
  SceneDesc scene = room();
  scene.sources[0].directivity.a = Bands(0.5f);  // cardioid, facing the near end wall (-x)
  scene.sources[0].rotation = glm::angleAxis(3.14159265f, glm::vec3(0, 0, 1));
  requireReciprocal(scene);
}

TEST_CASE("One pass from the listener serves every source of a many-source scene",
          "[engine][statistics]") {
  SceneDesc scene = room();
  for (const glm::vec3 p : {glm::vec3{1.f, 1.f, 1.f}, glm::vec3{9.f, 6.f, 2.5f},
                            glm::vec3{5.f, 3.5f, 0.6f}, glm::vec3{8.5f, 1.2f, 1.5f}}) {
    SourceDesc s = scene.sources[0];
    s.position = p;
    scene.sources.push_back(s);
  }
  requireReciprocal(scene);
}

TEST_CASE("Reciprocal tracing through a transmitting partition", "[engine][statistics]") {
  // A partition across the room (x = 5) with R = 10 dB (tau 0.1 <= its absorption 0.3):
  // source and listener on opposite sides, so every path passes through it at least once.
  // One sheet, not test::addPanel's double-sided panel, whose two faces would each apply R.
  SceneDesc scene = room();
  Material partition{"partition", Bands(0.3f), Bands(0.3f)};
  partition.transmissionLossDb = Bands(10.f);
  scene.materials.push_back(partition);
  const uint32_t v = uint32_t(scene.mesh.vertices.size());
  for (const glm::vec3 p : {glm::vec3{5, 0, 0}, glm::vec3{5, 7, 0}, glm::vec3{5, 7, 3},
                            glm::vec3{5, 0, 3}})
    scene.mesh.vertices.push_back(p);
  scene.mesh.triangles.push_back({v, v + 1, v + 2});
  scene.mesh.triangles.push_back({v, v + 2, v + 3});
  scene.mesh.materialIndex.resize(scene.mesh.triangles.size(), 0);
  scene.mesh.materialIndex.back() = scene.mesh.materialIndex[scene.mesh.materialIndex.size() - 2] = 1;
  requireReciprocal(scene);
}
