// dpc studio's heat map average (apps/studio/surface_heat.h): the first frame taken whole, then
// an exponential average with weight 1/K per frame (closed form: after n frames of value v
// following a first frame of u, the mean is v + (u - v)(1 - 1/K)^n), the band mean per
// surface, a new selection forgetting the old pair's surfaces, triangles beyond the geometry
// ignored.
#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

#include "apps/studio/surface_heat.h"

using namespace dpc;

namespace {

SurfaceTally::Surface surface(uint32_t t, float bandValue) { return {t, Bands(bandValue)}; }

}  // namespace

TEST_CASE("SurfaceHeat: the path cache's window as an exponential average per surface",
          "[studio]") {
  studio::SurfaceHeat heat(5, 4.0);
  std::vector<uint32_t> tri;
  std::vector<float> energy;
  Bands rising(0.f);
  for (int b = 0; b < kNumBands; ++b) rising[b] = float(b);  // band mean 3.5
  heat.add(std::vector<SurfaceTally::Surface>{{1, rising}, surface(3, 2.f), surface(9, 1.f)});
  heat.nonzero(tri, energy);
  REQUIRE(tri == std::vector<uint32_t>{1, 3});
  CHECK(energy[0] == Approx(3.5));
  CHECK(energy[1] == Approx(2.0));
  // Three frames in which surface 3 holds 6 and surface 1 nothing.
  for (int n = 0; n < 3; ++n) heat.add(std::vector<SurfaceTally::Surface>{surface(3, 6.f)});
  heat.nonzero(tri, energy);
  REQUIRE(tri == std::vector<uint32_t>{1, 3});
  CHECK(energy[0] == Approx(3.5 * std::pow(0.75, 3)));
  CHECK(energy[1] == Approx(6.0 + (2.0 - 6.0) * std::pow(0.75, 3)));
  heat.reset();
  heat.nonzero(tri, energy);
  CHECK(tri.empty());
  heat.add(std::vector<SurfaceTally::Surface>{surface(0, 1.f)});  // after a reset: taken whole
  heat.nonzero(tri, energy);
  REQUIRE(tri == std::vector<uint32_t>{0});
  CHECK(energy[0] == Approx(1.0));
}

TEST_CASE("SurfaceHeat: a window of one frame shows each frame alone", "[studio]") {
  studio::SurfaceHeat heat(2, 0.3);  // less than a frame: K = 1
  std::vector<uint32_t> tri;
  std::vector<float> energy;
  heat.add(std::vector<SurfaceTally::Surface>{surface(0, 1.f)});
  heat.add(std::vector<SurfaceTally::Surface>{surface(1, 2.f)});
  heat.nonzero(tri, energy);
  REQUIRE(tri == std::vector<uint32_t>{1});
  CHECK(energy[0] == Approx(2.0));
}
