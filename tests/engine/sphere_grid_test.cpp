// The sphere grid (engine/sphere_grid.h) and its use by the propagator for many receiver
// spheres: it must never miss a sphere a segment crosses nor offer one twice, so the hits
// through it equal, bit for bit, those of testing each sphere alone.
#include "engine/sphere_grid.h"

#include <catch2/catch.hpp>
#include <glm/geometric.hpp>
#include <set>
#include <vector>

#include "common/random.h"
#include "engine/embree_tracer.h"
#include "engine/propagation.h"
#include "engine/sampling.h"
#include "testing/test_scenes.h"
#include "testing/test_util.h"

using namespace dpc;

namespace {

/// Whether the segment org + t dir, t in [0, end], meets the sphere (the propagator's test).
bool meets(const glm::vec3& org, const glm::vec3& dir, float end, const glm::vec4& s) {
  const glm::vec3 oc = glm::vec3(s) - org;
  const float b = glm::dot(oc, dir);
  const float disc = b * b - (glm::dot(oc, oc) - s.w * s.w);
  if (!(disc > 0.f)) return false;
  const float r = std::sqrt(disc);
  return b + r > 0.f && b - r < end;
}

/// The spheres the grid offers the segment, and in `calls` how many times it called back.
std::set<uint32_t> offeredBy(const SphereGrid& grid, const glm::vec3& org, const glm::vec3& dir,
                             float end, size_t& calls) {
  std::set<uint32_t> candidates;
  calls = 0;
  grid.forEachCandidate(org, dir, end, [&](uint32_t i) {
    candidates.insert(i);
    ++calls;
  });
  return candidates;
}

}  // namespace

TEST_CASE("The sphere grid offers every sphere a segment meets, once", "[engine]") {
  Rng rng(5, 7);
  for (size_t n : {1, 5, 9, 64, 256}) {
    std::vector<glm::vec4> spheres;
    for (size_t i = 0; i < n; ++i)
      spheres.emplace_back(20.f * rng.uniform(), 10.f * rng.uniform(), 4.f * rng.uniform(),
                           0.1f + 0.9f * rng.uniform());
    SphereGrid grid;
    grid.build(spheres);
    REQUIRE(grid.size() == n);
    size_t met = 0, offered = 0;
    for (int k = 0; k < 20000; ++k) {
      const glm::vec3 org(20.f * rng.uniform(), 10.f * rng.uniform(), 4.f * rng.uniform());
      glm::vec3 dir = uniformSphere(rng);
      if (k % 50 == 0) dir = glm::vec3(0.f, 0.f, 1.f);  // axis-parallel: infinite slopes
      const float end = k % 3 == 0 ? INFINITY : 8.f * rng.uniform();
      size_t calls = 0;
      const std::set<uint32_t> candidates = offeredBy(grid, org, dir, end, calls);
      CHECK(calls == candidates.size());  // no sphere offered twice
      offered += candidates.size();
      for (uint32_t i = 0; i < n; ++i)
        if (meets(org, dir, end, spheres[i])) {
          ++met;
          CHECK(candidates.count(i) == 1);
        }
    }
    INFO(n << " spheres: " << met << " crossings, " << offered << " candidates offered");
    CHECK(met > 0);
    if (n >= 64) CHECK(offered < 20000 * n / 4);  // the grid prunes
  }
}

TEST_CASE("The sphere grid on a talkers' lattice: segments along cell planes and diagonals",
          "[engine]") {
  // 8 x 8 talkers 2 m apart at 1.5 m, radius 0.5 m (scenes/dense_hall.json's layout): the
  // grid's cell planes fall on round coordinates, where segments starting on a plane, running
  // along one or through a cell corner test the walk's rounding.
  std::vector<glm::vec4> spheres;
  for (int i = 0; i < 8; ++i)
    for (int j = 0; j < 8; ++j) spheres.emplace_back(3.f + 2.f * i, 1.5f, 1.5f + 2.f * j, 0.5f);
  SphereGrid grid;
  grid.build(spheres);
  Rng rng(11, 3);
  const glm::vec3 dirs[] = {{1, 0, 0},
                            {0, 0, 1},
                            {-1, 0, 0},
                            {0, 0, -1},
                            {0, 1, 0},
                            glm::normalize(glm::vec3(1, 0, 1)),
                            glm::normalize(glm::vec3(-1, 0, 1)),
                            glm::normalize(glm::vec3(1, 1, 1)),
                            glm::normalize(glm::vec3(1, -1, -1))};
  size_t met = 0;
  for (int k = 0; k < 20000; ++k) {
    // Origins on the lattice's round coordinates (multiples of 0.5 m) and between them.
    const auto coord = [&](float span) {
      return k % 2 ? 0.5f * std::floor(2.f * span * rng.uniform()) : span * rng.uniform();
    };
    const glm::vec3 org(coord(20.f), k % 3 ? 1.5f : coord(4.f), coord(17.f));
    const glm::vec3 dir = k % 4 ? dirs[size_t(k) % std::size(dirs)] : uniformSphere(rng);
    const float end = k % 5 == 0 ? INFINITY : 12.f * rng.uniform();
    size_t calls = 0;
    const std::set<uint32_t> candidates = offeredBy(grid, org, dir, end, calls);
    CHECK(calls == candidates.size());
    for (uint32_t i = 0; i < spheres.size(); ++i)
      if (meets(org, dir, end, spheres[i])) {
        ++met;
        CHECK(candidates.count(i) == 1);
      }
  }
  CHECK(met > 1000);
}

TEST_CASE("Through the grid each sphere gets the hits it gets alone", "[engine]") {
  SceneDesc sc = test::makeShoebox({10, 7, 3}, Bands(0.2f), 0.3f, {2, 2, 1.5f}, {7, 4, 1.6f});
  Geometry geometry(sc.mesh, sc.materials, sc.propagation.patchSize, sc.objects);
  EmbreeTracer tracer(sc.mesh, sc.objects);
  sc.propagation.raysPerFrame = 1024;
  sc.propagation.exactOrder = 0;
  Propagator propagator(geometry, tracer, sc.propagation);
  std::vector<ListenerSphere> spheres;
  for (int i = 0; i < 12; ++i)
    spheres.push_back(
        {{0.8f + 0.7f * i, 1.f + 0.4f * float(i % 5), 0.5f + 0.2f * float(i % 4)}, 0.4f});
  REQUIRE(spheres.size() > Propagator::kMaxLinearSpheres);
  std::vector<FrameGroups> groups(spheres.size());
  std::vector<FrameGroups*> ptrs;
  for (FrameGroups& g : groups) ptrs.push_back(&g);
  const glm::vec3 source = sc.sources[0].position;
  propagator.traceFrame(test::traceRequest(sc.propagation, 3, 0, source, spheres), ptrs);
  for (size_t s = 0; s < spheres.size(); ++s) {
    FrameGroups alone;
    propagator.traceFrame(
        test::traceRequest(sc.propagation, 3, 0, source, std::span(&spheres[s], 1)), alone);
    REQUIRE(alone.hitCount() > 0);
    REQUIRE(groups[s].groups().size() == alone.groups().size());
    for (size_t k = 0; k < alone.groups().size(); ++k) {
      CHECK(groups[s].groups()[k].eta == alone.groups()[k].eta);
      CHECK(groups[s].groups()[k].length == alone.groups()[k].length);
      CHECK(groups[s].groups()[k].intensity == alone.groups()[k].intensity);
    }
  }
}
