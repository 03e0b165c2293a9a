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

namespace dpc {

TEST_CASE("Wave band: a bake's receivers outside the air get no IR, the others the same bits",
          "[wave]") {
  const SceneDesc s = test::partitionedWaveBox();
  const Geometry geometry(s.mesh, s.materials, s.propagation.patchSize);
  const EmbreeTracer tracer(s.mesh);
  wave::WaveBandOptions opt;
  opt.seconds = 0.2;
  const glm::vec3 source(0.7f, 1.1f, 0.9f), inside(3.2f, 1.9f, 2.6f), outside(9.f, 1.f, 1.f);
  const wave::WavePoint one[] = {{inside, "receiver"}};
  const wave::WaveBand alone = wave::simulateWaveBand(s, tracer, geometry, {source, "source"},
                                                      one, opt);
  opt.allowUnreached = true;
  const wave::WavePoint both[] = {{outside, "probe 0"}, {inside, "probe 1"}};
  const wave::WaveBand bake = wave::simulateWaveBand(s, tracer, geometry, {source, "source"},
                                                     both, opt);
  CHECK(bake.reached == std::vector<uint8_t>{0, 1});
  CHECK(std::all_of(bake.irs[0].begin(), bake.irs[0].end(), [](float x) { return x == 0.f; }));
  // The air flooded from the source alone is the room's: the in-air receiver's IR is the one
  // it gets alone, bit for bit.
  CHECK(bake.irs[1] == alone.irs[0]);
  CHECK(alone.reached == std::vector<uint8_t>{1});
}

}  // namespace dpc
