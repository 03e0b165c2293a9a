// The wave band's solver against reciprocity: swapping source and receiver gives the same
// impulse response (the scheme's update, its walls and its trilinear source and receiver
// weights are symmetric), in a room that has no symmetry to hide an error: a box with a
// partial partition of another material, points off the grid's nodes.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>

#include "engine/embree_tracer.h"
#include "engine/geometry.h"
#include "testing/test_scenes.h"
#include "wave/wave_band.h"

namespace dpc {
namespace {

std::vector<float> response(const SceneDesc& s, glm::vec3 from, glm::vec3 to) {
  const Geometry geometry(s.mesh, s.materials, s.propagation.patchSize);
  const EmbreeTracer tracer(s.mesh);
  wave::WaveBandOptions opt;
  opt.seconds = 0.2;
  const wave::WavePoint at[] = {{to, "receiver"}};
  return wave::simulateWaveBand(s, tracer, geometry, {from, "source"}, at, opt).irs.front();
}

}  // namespace

TEST_CASE("Wave band: source and receiver swapped give the same IR", "[wave]") {
  const SceneDesc s = test::partitionedWaveBox();
  const glm::vec3 a(0.7f, 1.1f, 0.9f), b(3.2f, 1.9f, 2.6f);
  const std::vector<float> ab = response(s, a, b), ba = response(s, b, a);
  REQUIRE(ab.size() == ba.size());
  double peak = 0.0, diff = 0.0, energy = 0.0;
  for (size_t i = 0; i < ab.size(); ++i) {
    peak = std::max(peak, double(std::abs(ab[i])));
    diff = std::max(diff, double(std::abs(ab[i] - ba[i])));
    energy += double(ab[i]) * ab[i];
  }
  INFO("peak " << peak << ", largest difference " << diff);
  REQUIRE(energy > 0.0);
  // Float rounding of two different orders of the same sums over ~1,000 steps: 1e-4 of the
  // peak. A one-sided error (a wall seen from one side, a weight off by a node) is percents.
  CHECK(diff <= 1e-4 * peak);
}

TEST_CASE("Wave band: a point in the solid is refused with its field", "[wave]") {
  const SceneDesc s = test::partitionedWaveBox();
  CHECK_THROWS_WITH(response(s, {0.7f, 1.1f, 0.9f}, {9.f, 1.f, 1.f}),
                    Catch::Contains("receiver") && Catch::Contains("lies in no air"));
}

}  // namespace dpc
