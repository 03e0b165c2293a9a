// The memory budget on a real scene: the fully diffuse 10 x 7 x 3 m shoebox with a 1 MB budget
// against an unbounded cache (docs/estimators.md, "Memory budget").
#include <catch2/catch.hpp>
#include <cmath>

#include "engine/simulation.h"
#include "testing/test_scenes.h"

using namespace dpc;

namespace {

SceneDesc diffuseShoebox(DpcWeighting w, float budgetMb) {
  SceneDesc s = test::makeShoebox({10, 7, 3}, Bands(0.1f), 1.f, {2, 2, 1.5f}, {7, 4.5f, 1.6f});
  s.propagation.estimator = Estimator::kDpc;
  s.propagation.dpcWeighting = w;
  s.propagation.cacheTau = 1.f;
  s.propagation.frameRate = 15.f;
  s.propagation.raysPerFrame = 4096;
  s.propagation.maxOrder = 100;
  s.propagation.irLength = 2.f;
  s.propagation.cacheMemoryMb = budgetMb;
  s.propagation.diffraction = false;
  return s;
}

}  // namespace

// Both caches see the same rays (same seed), so their difference is the merge alone: the total
// energy may differ only by float rounding and the 10 ms band energies only by arrivals moved
// to their 1 ms coarse bin's mean delay. Tolerances: total 1e-3 relative (float bins summing
// ~10^3 terms each, EMA states decayed ~10^2 times, each a few ulp); 10 ms bins: the merge's
// L2 difference must stay below a fifth of the estimate's own Monte Carlo error, measured as
// the L2 change of the unbounded estimate between frames one window apart (statistically
// independent frames: the window and the EMA forget their terms after tau).
TEST_CASE("A 1 MB budget on the diffuse shoebox: bytes bounded, energy response unchanged",
          "[dpc][budget][heavy]") {
  for (DpcWeighting w : {DpcWeighting::kEma, DpcWeighting::kWindow}) {
    INFO("weighting " << int(w));
    Simulation small(diffuseShoebox(w, 1.f)), big(diffuseShoebox(w, 512.f));
    const glm::vec3 listener{7, 4.5f, 1.6f};
    const int frames = 32;
    std::vector<EnergyResponse> history;
    for (int f = 0; f < frames; ++f) {
      small.runFrame(listener);
      big.runFrame(listener);
      const auto& a = small.result(0);
      const auto& b = big.result(0);
      REQUIRE(a.cacheBudgetBytes == 1048576);
      REQUIRE(a.cacheBytes <= a.cacheBudgetBytes);
      REQUIRE(b.cacheMergedEntries == 0);
      const double ea = a.energy.total().average(), eb = b.energy.total().average();
      INFO("frame " << f << " 1 MB " << ea << " unbounded " << eb << " entries " << a.cacheEntries
                    << " / " << b.cacheEntries << " merged " << a.cacheMergedEntries);
      REQUIRE(std::abs(ea - eb) <= 1e-3 * eb);
      history.push_back(b.energy.rebinned(10));
      if (f < frames - 1) continue;
      // 10 ms band energies, L2 over bins and bands.
      const EnergyResponse ra = a.energy.rebinned(10), &rb = history.back();
      const EnergyResponse& rOld = history[size_t(f - 16)];
      double diff = 0, noise = 0, norm = 0;
      for (size_t k = 0; k < rb.binCount(); ++k)
        for (size_t band = 0; band < size_t(kNumBands); ++band) {
          const double x = rb.bins()[k][band];
          diff += std::pow(ra.bins()[k][band] - x, 2);
          noise += std::pow(rOld.bins()[k][band] - x, 2);
          norm += x * x;
        }
      const double relDiff = std::sqrt(diff / norm), relNoise = std::sqrt(noise / norm);
      INFO("10 ms bins: budget difference " << relDiff << ", Monte Carlo error " << relNoise
                                            << ", coarse share " << a.cacheCoarseEnergyFraction);
      CHECK(a.cacheMergedEntries > 10000);
      CHECK(a.cacheCoarseEnergyFraction > 0.1);
      CHECK(relDiff < 0.2 * relNoise);
      WARN("weighting " << int(w) << ": 1 MB budget, " << a.cacheEntries << " path entries ("
                        << b.cacheEntries << " unbounded), " << a.cacheMergedEntries
                        << " merged, coarse share " << a.cacheCoarseEnergyFraction
                        << ", 10 ms L2 difference " << relDiff << " vs Monte Carlo " << relNoise
                        << ", total energy ratio " << ea / eb);
    }
  }
}

// Order-adaptive identifiers (engine/patch.h, PathKeyRule): beyond the mixing-time order, hits
// are grouped by last triangle and 1 ms length bin. The estimators are linear in each group's
// per-frame sums and every group's mean delay stays in its energy bin, so the energy response
// equals the thesis identifier's up to float rounding (1e-5 in total), except that a group whose
// hits sit at a bin edge may land in the neighbouring 1 ms bin (length r / 0.343 m in float vs
// delay r / c in double): L2 difference over 1 ms bins below 1e-3 relative, while the window
// cache holds far fewer entries.
TEST_CASE("Order-adaptive path identifiers keep the energy response and shrink the cache",
          "[dpc][budget][heavy]") {
  const SceneDesc scene = diffuseShoebox(DpcWeighting::kWindow, 512.f);
  Simulation adaptive(scene);
  Simulation::Options thesisRule;
  thesisRule.keyRule = PathKeyRule{};
  Simulation thesis(scene, scene.propagation, thesisRule);
  CHECK(adaptive.propagator().pathKeyRule().fullOrder == PathKeyRule::kMinFullOrder);
  const glm::vec3 listener{7, 4.5f, 1.6f};
  for (int f = 0; f < 16; ++f) {
    adaptive.runFrame(listener);
    thesis.runFrame(listener);
  }
  const auto& a = adaptive.result(0);
  const auto& b = thesis.result(0);
  const double ta = a.energy.total().average(), tb = b.energy.total().average();
  CHECK(std::abs(ta - tb) <= 1e-5 * tb);
  double diff = 0, norm = 0;
  for (size_t k = 0; k < b.energy.binCount(); ++k) {
    const double x = b.energy.bins()[k].average(), y = a.energy.bins()[k].average();
    diff += (x - y) * (x - y);
    norm += x * x;
  }
  INFO("1 ms bins: relative L2 difference " << std::sqrt(diff / norm));
  CHECK(std::sqrt(diff / norm) < 1e-3);
  WARN("window cache entries after 16 frames: adaptive " << a.cacheEntries << ", thesis "
                                                         << b.cacheEntries);
  CHECK(a.cacheEntries * 2 < b.cacheEntries);
}

// A budget too small for the cache's tables is refused with the budget the settings need: that
// budget fits and one byte less does not (the message once quoted a "minimum" below the budget
// it refused), and a window of more frames than the coarse store can layer is refused whatever
// the budget. A budget that fits is never refused by the smaller first tables grown from it.
TEST_CASE("The path cache's budget check names a budget that fits", "[cache]") {
  using Cache = DiffusePathCache;
  const double period = 1.0 / 120.0;
  for (const double tau : {0.5, 10.0, 30.0}) {
    INFO("tau " << tau << " s at 120 Hz");
    std::string message;
    try {
      Cache::capacityFor(DpcWeighting::kWindow, tau, period, 4096);
    } catch (const std::invalid_argument& e) {
      message = e.what();
    }
    REQUIRE(message.rfind("cache_memory_mb: a budget of 4096 bytes", 0) == 0);
    const size_t at = message.find("below the ") + 10;
    const size_t need = std::stoull(message.substr(at));
    CHECK(Cache::capacityFor(DpcWeighting::kWindow, tau, period, need).bytes <= need);
    CHECK_THROWS_AS(Cache::capacityFor(DpcWeighting::kWindow, tau, period, need - 1),
                    std::invalid_argument);
    // The cache itself, built at that budget, starts (its first tables are a smaller split).
    CHECK_NOTHROW(Cache(DpcWeighting::kWindow, tau, period, need));
  }
  CHECK_THROWS_WITH(Cache::capacityFor(DpcWeighting::kWindow, 100.0, period, size_t(1) << 30),
                    Catch::StartsWith("cache_tau: 12000 frames of paths"));
}
