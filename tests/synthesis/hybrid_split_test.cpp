// Hybrid rendering's early/late split (synthesis/hybrid_split.h) and the clusters of sources
// that share a late bus (synthesis/source_clusters.h).
#include <catch2/catch.hpp>
#include <cmath>
#include <random>
#include <vector>

#include "synthesis/hybrid_split.h"
#include "synthesis/source_clusters.h"

using namespace dpc;

namespace {

EnergyResponse randomResponse(uint32_t seed) {
  EnergyResponse r(0.5, 1e-3);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  for (Bands& b : r.bins())
    for (int k = 0; k < kNumBands; ++k) b[k] = u(rng);
  return r;
}

SourceClusters::Visible allVisible() {
  return [](const glm::vec3&, const glm::vec3&) { return true; };
}

glm::vec3 onCircle(double degrees, float r = 5.f) {
  const double a = degrees * M_PI / 180.0;
  return {r * float(std::cos(a)), 0.f, r * float(std::sin(a))};
}

}  // namespace

// Oracle: energy conservation, bin by bin (the early and late parts are independent noise, so
// their energies add); tolerance float rounding of one product.
TEST_CASE("Early and late parts add up to the response, bin by bin", "[synthesis][hybrid]") {
  const EnergyResponse r = randomResponse(7);
  const HybridSplit split{0.2, 0.01};
  EnergyResponse early = r, late(0.5, 1e-3);
  keepEarly(early, split);
  const LateShare share = addLate(r, DirectSound{}, {}, split, late);
  double lateTotal = 0.0;
  for (size_t k = 0; k < r.binCount(); ++k) {
    for (int b = 0; b < kNumBands; ++b)
      CHECK(early.bins()[k][b] + late.bins()[k][b] == Approx(r.bins()[k][b]).epsilon(1e-6));
    lateTotal += double(late.bins()[k].sum());
  }
  CHECK(share.energy == Approx(lateTotal).epsilon(1e-9));
  CHECK(early.bins()[189][0] == r.bins()[189][0]);  // before the fade: whole
  CHECK(early.bins()[200][0] == 0.f);                // at the split: nothing early
  CHECK(late.bins()[100][3] == 0.f);
}

// Oracle: an arrival placed exactly must not vanish when it falls after the early part: its
// energy moves into the late part's bin of its delay.
TEST_CASE("Arrivals after the early part move into the late part", "[synthesis][hybrid]") {
  const HybridSplit split{0.1, 0.01};
  EnergyResponse r(0.5, 1e-3), late(0.5, 1e-3);
  DirectSound direct;
  direct.visible = true;
  direct.delaySeconds = 0.3f;
  direct.intensity = Bands(2.f);
  std::vector<SpecularPath> paths(2);
  paths[0].delaySeconds = 0.05;
  paths[0].intensity = Bands(1.f);
  paths[1].delaySeconds = 0.095;  // inside the fade: late, as a whole
  paths[1].intensity = Bands(0.5f);
  const LateShare share = addLate(r, direct, paths, split, late);
  CHECK(share.directIsLate);
  CHECK(share.lateArrivals == 2);
  CHECK(late.bins()[300][4] == 2.f);
  CHECK(late.bins()[95][4] == 0.5f);
  CHECK(share.energy == Approx(8 * 2.5));
  std::vector<SpecularPath> early;
  earlyPaths(paths, split, early);
  REQUIRE(early.size() == 1);
  CHECK(early[0].delaySeconds == 0.05);
  CHECK(hybridEarlyLength(34.3, 343.0, 2.0, 0.01) == Approx(0.1 + kHybridEarlySeconds + 0.01));
  CHECK(hybridEarlyLength(3430.0, 343.0, 2.0, 0.01) == 2.0);
}

// Oracle: geometry: two groups 90 degrees apart as seen from the listener, each within 10
// degrees, form two clusters under a 30-degree bound, every member within it.
TEST_CASE("Sources cluster by direction from the listener", "[synthesis][hybrid]") {
  std::vector<glm::vec3> pos;
  for (double a : {0.0, 5.0, -8.0, 90.0, 95.0, 84.0}) pos.push_back(onCircle(a));
  SourceClusters c(pos.size(), 4, 30.0 * M_PI / 180.0);
  c.update({0, 0, 0}, pos, allVisible());
  CHECK(c.occupied() == 2);
  CHECK(c.cluster(0) == c.cluster(1));
  CHECK(c.cluster(0) == c.cluster(2));
  CHECK(c.cluster(3) == c.cluster(4));
  CHECK(c.cluster(3) == c.cluster(5));
  CHECK(c.cluster(0) != c.cluster(3));
  CHECK(c.maxAngularRadius() < 30.0 * M_PI / 180.0);
  CHECK(c.forcedJoins() == 0);
}

// Oracle: the visibility criterion: sources in the same direction that cannot see each other
// (another room) do not share a bus.
TEST_CASE("Mutually invisible sources do not share a cluster", "[synthesis][hybrid]") {
  std::vector<glm::vec3> pos = {onCircle(0.0, 3.f), onCircle(2.0, 9.f)};
  SourceClusters c(pos.size(), 4, 30.0 * M_PI / 180.0);
  c.update({0, 0, 0}, pos, [](const glm::vec3&, const glm::vec3&) { return false; });
  CHECK(c.cluster(0) != c.cluster(1));
  c.update({0, 0, 0}, pos, allVisible());  // now visible: still apart, each keeps its bus
  CHECK(c.switches() == 0);
}

// Oracle: hysteresis: a source joins a cluster within 30 degrees of its mean direction and
// leaves it only beyond 1.25 x 30 degrees. With two sources the mean lies half-way, so a second
// source that wanders between 28 and 60 degrees from the first (14 to 30 degrees from the mean)
// stays, though beyond 30 degrees it could not join; at 80 degrees (40 from the mean) it
// leaves, once, and that is counted.
TEST_CASE("Cluster membership does not flicker at a boundary", "[synthesis][hybrid]") {
  SourceClusters c(2, 4, 30.0 * M_PI / 180.0);
  for (int f = 0; f < 100; ++f) {
    const double b = 28.0 + 16.0 * (1.0 - std::cos(0.7 * f));
    const std::vector<glm::vec3> pos = {onCircle(0.0), onCircle(b)};
    c.update({0, 0, 0}, pos, allVisible());
    CHECK(c.cluster(1) == c.cluster(0));
  }
  CHECK(c.switches() == 0);
  const std::vector<glm::vec3> far = {onCircle(0.0), onCircle(80.0)};
  c.update({0, 0, 0}, far, allVisible());
  CHECK(c.cluster(1) != c.cluster(0));
  CHECK(c.switches() == 1);
}

// Oracle: the bus budget: six directions 60 degrees apart need six clusters; with four buses
// every source still gets one, and the two that did not fit are counted.
TEST_CASE("More directions than buses: every source assigned, the overflow counted",
          "[synthesis][hybrid]") {
  std::vector<glm::vec3> pos;
  for (int i = 0; i < 6; ++i) pos.push_back(onCircle(60.0 * i));
  SourceClusters c(pos.size(), 4, 20.0 * M_PI / 180.0);
  c.update({0, 0, 0}, pos, allVisible());
  for (size_t s = 0; s < pos.size(); ++s) CHECK(c.cluster(s) != SourceClusters::kNone);
  CHECK(c.occupied() == 4);
  CHECK(c.forcedJoins() == 2);
}

// Oracle: a static scene has nothing to follow: eight sources 45 degrees apart need eight
// clusters under a 30-degree bound; with four buses the four that fit none join one each
// frame for want of a bus, and must join the same one every frame (the shoebox with eight
// talkers switched 202 times in 203 frames, and its late tails' T30 read 8-9 % off the
// sources' own while the buses' mixes changed under them). The bus's members that fit
// within the bound keep their mean direction: a source joined beyond it moves none of them.
TEST_CASE("More directions than buses, static: nobody changes bus between frames",
          "[synthesis][hybrid]") {
  std::vector<glm::vec3> pos;
  for (int i = 0; i < 8; ++i) pos.push_back(onCircle(45.0 * i, 2.f + 0.3f * float(i)));
  SourceClusters c(pos.size(), 4, 30.0 * M_PI / 180.0);
  c.update({0, 0, 0}, pos, allVisible());
  std::vector<int> first;
  for (size_t s = 0; s < pos.size(); ++s) first.push_back(c.cluster(s));
  for (int f = 1; f < 50; ++f) {
    c.update({0, 0, 0}, pos, allVisible());
    for (size_t s = 0; s < pos.size(); ++s) CHECK(c.cluster(s) == first[s]);
  }
  CHECK(c.switches() == 0);
  CHECK(c.occupied() == 4);
  CHECK(c.forcedJoins() == 4 * 50);                   // source-frames joined beyond the bound
  CHECK(c.maxAngularRadius() < 30.0 * M_PI / 180.0);  // the members that fit, as they fit
}
