// The window DPC's ring of per-frame terms (engine/path_cache_weightings.h) while its budget is
// spent: the path table is full and merges its oldest entries into the coarse store with the
// ring shorter than the terms' capacity, wrapped, and widening. The oracle is an unbounded cache
// fed the same frames (no merge, no wrap of a full ring): every weighting's readout is linear in
// the merged state, so the total energy read out agrees within float rounding of the energy
// response's bins (up to ~3,000 terms into one bin, 3,000 * 1.2e-7 = 4e-4 relative; 1e-3 used).
#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

#include "common/random.h"
#include "engine/path_cache.h"

using namespace dpc;

namespace {

constexpr float kC = 343.f;

EnergyResponse runFrame(DiffusePathCache& cache, const std::vector<PathHit>& hits) {
  FrameGroups g;
  for (const PathHit& h : hits) g.add(h);
  EnergyResponse out(1.0, 1e-3);
  cache.endFrame(g, 100, kC, out);
  return out;
}

PathHit hitOf(uint64_t key) {
  PathHit h;
  h.key = key;
  h.intensity = Bands(1.f + float(key % 7));
  h.length = 10.f + float(key % 50) * 3.f;
  h.direction = {1.f, 0.f, 0.f};
  return h;
}

}  // namespace

TEST_CASE("Window DPC: merges with a short, wrapped ring keep the window's energy", "[dpc]") {
  const double tau = 0.5, period = 0.1;  // W = 5 frames
  size_t budget = 1u << 20;
  while (DiffusePathCache::capacityFor(DpcWeighting::kWindow, tau, period, budget).entries < 4000)
    budget += 1u << 16;
  DiffusePathCache cache(DpcWeighting::kWindow, tau, period, budget);
  DiffusePathCache unbounded(DpcWeighting::kWindow, tau, period, 256u << 20);
  Rng rng(5, 11);
  for (uint64_t f = 0; f < 60; ++f) {
    // 800-2,200 new paths a frame (the window holds about 7,500, more than the table) and 400
    // re-hits of paths up to 6 frames old: about 1.1 terms per entry, so the table fills before
    // the ring, which merges find shorter than the terms' capacity and often wrapped.
    std::vector<PathHit> hits;
    const uint64_t fresh = 800 + rng.nextU32() % 1400;
    for (uint64_t i = 0; i < fresh; ++i) hits.push_back(hitOf(f * 10000 + i));
    for (int k = 0; k < 400; ++k) {
      const uint64_t g = f - std::min<uint64_t>(f, rng.nextU32() % 6);
      hits.push_back(hitOf(g * 10000 + rng.nextU32() % 800));
    }
    const EnergyResponse capped = runFrame(cache, hits);
    const EnergyResponse ref = runFrame(unbounded, hits);
    const double a = capped.total()[0], e = ref.total()[0];
    INFO("frame " << f << " capped " << a << " unbounded " << e);
    REQUIRE(std::abs(a - e) <= 1e-3 * e);
    REQUIRE(cache.bytesInUse() <= cache.bytes());
  }
  CHECK(unbounded.mergedEntries() == 0);
  CHECK(cache.mergedEntries() > 1000);
}
