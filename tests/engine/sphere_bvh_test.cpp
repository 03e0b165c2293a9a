// The sphere hierarchy (engine/sphere_bvh.h) and its use by the propagator for many receiver
// spheres: it must never miss a sphere a segment crosses, so the hits through it equal, bit for
// bit, those of testing each sphere alone.
#include <catch2/catch.hpp>
#include <glm/geometric.hpp>
#include <set>
#include <vector>

#include "common/random.h"
#include "engine/embree_tracer.h"
#include "engine/propagation.h"
#include "engine/sampling.h"
#include "engine/sphere_bvh.h"
#include "testing/test_util.h"
#include "testing/test_scenes.h"

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

}  // namespace

TEST_CASE("The sphere hierarchy offers every sphere a segment meets", "[engine]") {
  Rng rng(5, 7);
  for (size_t n : {1, 5, 9, 64, 256}) {
    std::vector<glm::vec4> spheres;
    for (size_t i = 0; i < n; ++i)
      spheres.emplace_back(20.f * rng.uniform(), 10.f * rng.uniform(), 4.f * rng.uniform(),
                           0.1f + 0.9f * rng.uniform());
    SphereBvh bvh;
    bvh.build(spheres);
    REQUIRE(bvh.size() == n);
    size_t met = 0, offered = 0;
    for (int k = 0; k < 20000; ++k) {
      const glm::vec3 org(20.f * rng.uniform(), 10.f * rng.uniform(), 4.f * rng.uniform());
      glm::vec3 dir = uniformSphere(rng);
      if (k % 50 == 0) dir = glm::vec3(0.f, 0.f, 1.f);  // axis-parallel: infinite slopes
      const float end = k % 3 == 0 ? INFINITY : 8.f * rng.uniform();
      std::set<uint32_t> candidates;
      bvh.forEachCandidate(org, dir, end, [&](uint32_t i) { candidates.insert(i); });
      offered += candidates.size();
      for (uint32_t i = 0; i < n; ++i)
        if (meets(org, dir, end, spheres[i])) {
          ++met;
          CHECK(candidates.count(i) == 1);
        }
    }
    INFO(n << " spheres: " << met << " crossings, " << offered << " candidates offered");
    CHECK(met > 0);
    if (n >= 64) CHECK(offered < 20000 * n / 4);  // the hierarchy prunes
  }
}

TEST_CASE("Through the hierarchy each sphere gets the hits it gets alone", "[engine]") {
  SceneDesc sc = test::makeShoebox({10, 7, 3}, Bands(0.2f), 0.3f, {2, 2, 1.5f}, {7, 4, 1.6f});
  Geometry geometry(sc.mesh, sc.materials, sc.propagation.patchSize, sc.objects);
  EmbreeTracer tracer(sc.mesh, sc.objects);
  sc.propagation.raysPerFrame = 1024;
  sc.propagation.exactOrder = 0;
  Propagator propagator(geometry, tracer, sc.propagation);
  std::vector<ListenerSphere> spheres;
  for (int i = 0; i < 12; ++i)
    spheres.push_back({{0.8f + 0.7f * i, 1.f + 0.4f * float(i % 5), 0.5f + 0.2f * float(i % 4)},
                       0.4f});
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
