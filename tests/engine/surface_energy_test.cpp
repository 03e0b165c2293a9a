// Where the energy comes from: each pair's per-surface tally (Simulation::recordSurfaces,
// SourceResult::surfaces, what dpc studio's heat map draws) against physics and against the
// frame's own response.
//  - A room whose walls and ceiling absorb everything and whose floor reflects specularly:
//    all reflected energy arrives from the floor, and its amount is the image source's,
//    (1 - alpha) / (4 pi r'^2) with r' the image distance (no air absorption), within the
//    Monte Carlo error of the hits counted (stated below); every other surface holds nothing.
//  - In a diffuse room, the tally summed over surfaces is the frame's path-traced response
//    summed over time, band by band (the same hits, grouped two ways).
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>
#include <vector>

#include "engine/simulation.h"
#include "testing/test_scenes.h"

using namespace dpc;

namespace {

/// Summed tally of the triangles [first, last) at band b, and of the rest.
std::pair<double, double> split(const SurfaceTally& t, uint32_t first, uint32_t last, int b) {
  double in = 0.0, out = 0.0;
  for (const SurfaceTally::Surface& f : t.surfaces())
    (f.triangle >= first && f.triangle < last ? in : out) += f.intensity[b];
  return {in, out};
}

}  // namespace

TEST_CASE("Surface tally: a reflecting floor in an anechoic box holds the image source's energy",
          "[surfaces]") {
  const glm::vec3 src(2.f, 1.5f, 2.f), lis(7.f, 1.6f, 5.f);
  SceneDesc s = test::makeShoebox({10, 3, 7}, Bands(1.f), 0.f, src, lis, 0.5f);
  constexpr float kAlpha = 0.3f;
  s.materials.push_back(Material{"floor", Bands(kAlpha), Bands(0.f)});
  s.mesh.materialIndex[4] = s.mesh.materialIndex[5] = 1;  // the y = 0 quad
  s.propagation.raysPerFrame = 200000;
  s.propagation.estimator = Estimator::kPathTracing;
  s.propagation.exactOrder = 0;
  s.propagation.airAbsorption = false;
  s.propagation.irLength = 0.2f;
  Simulation sim(s);
  sim.recordSurfaces(true);
  const double image = std::hypot(double(lis.x - src.x), double(lis.y + src.y),
                                  double(lis.z - src.z));
  const double expected = (1.0 - kAlpha) / (4.0 * std::numbers::pi * image * image);
  // Each floor hit carries the same intensity (specular, one reflection), so a frame's sum
  // counts hits: its relative standard error is 1 / sqrt(expected hits), the rays' share that
  // crosses the sphere, pi R^2 / (4 pi r'^2). Over the frames, 4 sigma; plus 1 % for the
  // sphere's own averaging of the 1/r^2 field over its cross-section, (R / r')^2 / 2.
  constexpr int kFrames = 6;
  const double hits = kFrames * s.propagation.raysPerFrame * 0.25 / (4.0 * image * image);
  double floor = 0.0, rest = 0.0;
  for (int f = 0; f < kFrames; ++f) {
    sim.runFrame(lis);
    const auto [in, out] = split(sim.result(0).surfaces, 4, 6, 4);
    floor += in / kFrames;
    rest += out / kFrames;
  }
  INFO("floor " << floor << " expected " << expected << " (" << hits << " hits expected)");
  CHECK(std::abs(floor / expected - 1.0) <= 4.0 / std::sqrt(hits) + 0.01);
  CHECK(rest == 0.0);
}

namespace {

/// Energy arriving last from the floor (y = 0) and from the ceiling (y = h) between two
/// specular planes of absorption aFloor and aCeiling, the walls anechoic: every image source
/// of the pair of planes up to order 60, by the plane of its last reflection,
/// (1 - a)... / (4 pi r^2) (Kuttruff, Room Acoustics, section 4.1).
std::pair<double, double> planeImages(glm::vec3 s, glm::vec3 l, double h, double aFloor,
                                      double aCeiling) {
  struct Image {
    double y, gain;
    int last;  ///< 0 floor, 1 ceiling, -1 none
  };
  std::vector<Image> level{{double(s.y), 1.0, -1}};
  const double d2 = std::pow(double(l.x - s.x), 2) + std::pow(double(l.z - s.z), 2);
  double sum[2] = {0.0, 0.0};
  for (int order = 1; order <= 60; ++order) {
    std::vector<Image> next;
    for (const Image& im : level)
      for (int plane = 0; plane < 2; ++plane) {
        if (plane == im.last) continue;
        const Image r{plane == 0 ? -im.y : 2.0 * h - im.y,
                      im.gain * (1.0 - (plane == 0 ? aFloor : aCeiling)), plane};
        sum[plane] += r.gain / (4.0 * std::numbers::pi * (d2 + std::pow(double(l.y) - r.y, 2)));
        next.push_back(r);
      }
    level = std::move(next);
  }
  return {sum[0], sum[1]};
}

}  // namespace

TEST_CASE("Surface tally: between a floor and a ceiling, energy goes to the last reflection's "
          "surface, traced from either end", "[surfaces]") {
  const glm::vec3 src(2.f, 2.4f, 2.f), lis(7.f, 0.6f, 5.f);
  SceneDesc s = test::makeShoebox({10, 3, 7}, Bands(1.f), 0.f, src, lis, 0.5f);
  s.materials.push_back(Material{"floor", Bands(0.3f), Bands(0.f)});
  s.materials.push_back(Material{"ceiling", Bands(0.6f), Bands(0.f)});
  s.mesh.materialIndex[4] = s.mesh.materialIndex[5] = 1;  // y = 0
  s.mesh.materialIndex[6] = s.mesh.materialIndex[7] = 2;  // y = 3
  s.propagation.raysPerFrame = 100000;
  s.propagation.estimator = Estimator::kPathTracing;
  s.propagation.exactOrder = 0;
  s.propagation.airAbsorption = false;
  const auto [floorExpected, ceilingExpected] = planeImages(src, lis, 3.0, 0.3, 0.6);
  for (Tracing tracing : {Tracing::kFromSources, Tracing::kFromListeners}) {
    s.propagation.tracing = tracing;
    Simulation sim(s);
    sim.recordSurfaces(true);
    // Mean and standard error of each plane's tally over independent frames; 4 standard
    // errors, plus 1 % for the sphere's averaging of the field over its cross-section.
    constexpr int kFrames = 10;
    double sum[2] = {0, 0}, sum2[2] = {0, 0};
    for (int f = 0; f < kFrames; ++f) {
      sim.runFrame(lis);
      const double v[2] = {split(sim.result(0).surfaces, 4, 6, 4).first,
                           split(sim.result(0).surfaces, 6, 8, 4).first};
      for (int p = 0; p < 2; ++p) sum[p] += v[p], sum2[p] += v[p] * v[p];
    }
    const double expected[2] = {floorExpected, ceilingExpected};
    for (int p = 0; p < 2; ++p) {
      const double mean = sum[p] / kFrames;
      const double se = std::sqrt((sum2[p] / kFrames - mean * mean) / (kFrames - 1));
      INFO((tracing == Tracing::kFromSources ? "from sources" : "from listeners")
           << (p ? ", ceiling " : ", floor ") << mean << " expected " << expected[p] << " +- "
           << se);
      CHECK(std::abs(mean - expected[p]) <= 4.0 * se + 0.01 * expected[p]);
    }
  }
}

TEST_CASE("Surface tally: summed over surfaces it is the frame's path-traced response",
          "[surfaces]") {
  SceneDesc s = test::makeShoebox({6, 3, 4}, Bands(0.2f), 0.6f, {1.5f, 1.2f, 1.f},
                                  {4.2f, 1.6f, 2.9f});
  s.propagation.raysPerFrame = 4000;
  s.propagation.estimator = Estimator::kPathTracing;
  s.propagation.exactOrder = 0;
  s.propagation.irLength = 3.f;  // every hit within the response (roulette ends them sooner)
  Simulation sim(s);
  sim.recordSurfaces(true);
  sim.runFrame(s.listeners[0].position);
  sim.runFrame(s.listeners[0].position);
  const Simulation::SourceResult& r = sim.result(0);
  REQUIRE(r.surfaces.surfaces().size() == 12);  // every wall triangle sends some energy
  for (int b = 0; b < kNumBands; ++b) {
    double tally = 0.0, response = 0.0;
    for (const SurfaceTally::Surface& f : r.surfaces.surfaces()) tally += f.intensity[b];
    for (const Bands& bin : r.energy.bins()) response += bin[b];
    INFO("band " << b << ": tally " << tally << ", response " << response);
    // The same float intensities summed in two orders (per surface, per 1 ms bin): rounding.
    CHECK(tally == Approx(response).epsilon(1e-4));
  }
  // Off again: nothing recorded.
  sim.recordSurfaces(false);
  sim.runFrame(s.listeners[0].position);
  CHECK(sim.result(0).surfaces.surfaces().empty());
}
