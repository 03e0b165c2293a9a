// Helpers shared by the dpc-bench subcommands: statistics, the options every scene benchmark
// takes, and the JSON report.
#pragma once

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "scene/scene.h"

namespace dpc::bench {

using Json = nlohmann::ordered_json;

/// The p-quantile (0..1) of v by linear interpolation between order statistics; NaN if empty.
inline double percentile(std::vector<double> v, double p) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  const double idx = p * double(v.size() - 1);
  const size_t lo = size_t(std::floor(idx)), hi = size_t(std::ceil(idx));
  return v[lo] + (v[hi] - v[lo]) * (idx - double(lo));
}

/// {"median", "p95", "min", "max"} of v, each multiplied by scale; NaN for an empty v.
Json stats(const std::vector<double>& v, double scale = 1.0);

/// The options of every benchmark that loads a scene. An empty optional: the scene's value
/// (or the benchmark's own default).
struct CommonOptions {
  std::string scene;
  int threads = 0;  ///< tracing threads (0 = all cores)
  int frames = 30;  ///< frames to measure
  std::optional<int> rays, maxOrder;
  std::optional<double> tau;      ///< cache response time, seconds
  std::optional<double> cacheMb;  ///< DPC memory budget per source, MB
};

/// The scene with only its first source (benchmarks time one source's frame).
SceneDesc firstSourceOnly(SceneDesc scene);

/// The scene's propagation settings with the common options applied.
PropagationSettings settingsFor(const SceneDesc& scene, const CommonOptions& c);

/// Name of the estimator as the reports print it ("dpc" or "path_tracing").
const char* estimatorName(Estimator estimator);

/// Prints the report on stdout, indented by 2, and a newline.
void printReport(const Json& j);

}  // namespace dpc::bench
