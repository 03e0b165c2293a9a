// `dpc-bench budget`: a budgeted and an unbounded cache on the same rays.
#include "bench/budget_bench.h"

#include <cmath>
#include <cstdio>

#include "engine/simulation.h"
#include "scene/trajectory.h"
#include "testing/test_scenes.h"
#include "scene/limits.h"

namespace dpc::bench {
namespace {

/// The scene of the sweep: the built-in room, or the file's first source.
SceneDesc budgetScene(const std::string& name) {
  if (name == "room-4x3x2.5")
    return test::makeShoebox({4, 3, 2.5f}, Bands(0.1f), 1.f, {1, 1, 1.2f}, {3, 2, 1.5f});
  return firstSourceOnly(loadScene(name));
}

const char* weightingName(DpcWeighting w) {
  return w == DpcWeighting::kWindow ? "window" : w == DpcWeighting::kEma ? "ema" : "seed";
}

/// One point of the sweep: `frames` frames at `rays` rays, budgeted against unbounded.
Json sweepPoint(const SceneDesc& scene, const PropagationSettings& s, int rays, int frames) {
  PropagationSettings a = s, b = s;
  a.raysPerFrame = b.raysPerFrame = rays;
  b.cacheMemoryMb = float(limitOf("propagation.cache_memory_mb").max);  // the largest allowed
  Simulation small(scene, a), big(scene, b);
  size_t maxBytes = 0;
  const glm::vec3 at = listenerPositionAt(scene.listeners[0], 0.0);
  for (int f = 0; f < frames; ++f) {
    small.runFrame(at);
    big.runFrame(at);
    maxBytes = std::max(maxBytes, small.result(0).cacheBytes);
  }
  const auto& x = small.result(0);
  const auto& y = big.result(0);
  const double ex = x.energy.total().average(), ey = y.energy.total().average();
  Json p;
  p["rays_per_frame"] = rays;
  p["entries"] = x.cacheEntries;
  p["coarse_entries"] = x.cacheCoarseEntries;
  p["bytes"] = maxBytes;
  p["budget_bytes"] = x.cacheBudgetBytes;
  p["entries_merged"] = x.cacheMergedEntries;
  p["merged_energy_fraction"] = x.cacheCoarseEnergyFraction;
  p["unbounded_entries"] = y.cacheEntries;
  p["energy_ratio_vs_unbounded"] = ey > 0.0 ? ex / ey : 1.0;
  p["g_difference_db"] = ey > 0.0 ? 10.0 * std::log10(ex / ey) : 0.0;
  std::fprintf(stderr, "%d rays: entries %zu (unbounded %zu), merged %llu, energy ratio %.6f\n",
               rays, x.cacheEntries, y.cacheEntries, (unsigned long long)x.cacheMergedEntries,
               ex / ey);
  return p;
}

}  // namespace

int benchBudget(const CommonOptions& c, const std::vector<int>& raysList) {
  const SceneDesc scene = budgetScene(c.scene);
  PropagationSettings s = settingsFor(scene, c);
  s.estimator = Estimator::kDpc;
  s.diffraction = false;
  const int frames = std::max(1, c.frames);
  Json j;
  j["benchmark"] = "budget";
  j["scene"] = c.scene;
  j["budget_mb"] = s.cacheMemoryMb;
  j["weighting"] = weightingName(s.dpcWeighting);
  j["tau_s"] = s.cacheTau;
  j["frames"] = frames;
  Json points = Json::array();
  for (int rays : raysList) points.push_back(sweepPoint(scene, s, rays, frames));
  j["points"] = points;
  printReport(j);
  return 0;
}

}  // namespace dpc::bench
