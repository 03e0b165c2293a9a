// Helpers shared by the dpc-bench subcommands.
#include "bench/bench_util.h"
#include "scene/validate.h"

#include <cstdio>

namespace dpc::bench {

Json stats(const std::vector<double>& v, double scale) {
  std::vector<double> s(v);
  for (double& x : s) x *= scale;
  return {{"median", percentile(s, 0.5)},
          {"p95", percentile(s, 0.95)},
          {"min", s.empty() ? NAN : *std::min_element(s.begin(), s.end())},
          {"max", s.empty() ? NAN : *std::max_element(s.begin(), s.end())}};
}

SceneDesc firstSourceOnly(SceneDesc scene) {
  scene.sources.resize(1);
  return scene;
}

PropagationSettings settingsFor(const SceneDesc& scene, const CommonOptions& c) {
  PropagationSettings s = scene.propagation;
  s.threads = c.threads;
  // The flags' ranges are the scene keys' (scene/limits.h).
  const Origin flags = commandLineOrigin();
  if (c.rays) checkField("propagation.rays_per_frame", *c.rays, flags);
  if (c.maxOrder) checkField("propagation.max_order", *c.maxOrder, flags);
  if (c.rays) s.raysPerFrame = *c.rays;
  if (c.maxOrder) s.maxOrder = *c.maxOrder;
  if (c.tau) s.cacheTau = checkFloatField("propagation.cache_tau", *c.tau, flags);
  if (c.cacheMb)
    s.cacheMemoryMb = checkFloatField("propagation.cache_memory_mb", *c.cacheMb, flags);
  return s;
}

const char* estimatorName(Estimator estimator) {
  return estimator == Estimator::kDpc ? "dpc" : "path_tracing";
}

void printReport(const Json& j) {
  std::printf("%s\n", j.dump(2).c_str());
}

}  // namespace dpc::bench
