#include "engine/workload.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "common/input_error.h"
#include "engine/cache_pool.h"
#include "engine/path_cache.h"
#include "engine/propagation.h"
#include "scene/tracing_policy.h"

namespace dpc {

namespace {
std::string g3(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", x);
  return buf;
}
}  // namespace

double plannableMemoryBytes() {
  double limit = double(sysconf(_SC_PHYS_PAGES)) * double(sysconf(_SC_PAGESIZE));
  for (const int which : {RLIMIT_AS, RLIMIT_DATA}) {
    rlimit rl{};
    if (getrlimit(which, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY)
      limit = std::min(limit, double(rl.rlim_cur));
  }
  return 0.5 * limit;
}

double cachePoolMbFor(const PropagationSettings& settings, size_t pairs) {
  if (settings.cachePoolMb != kCachePoolAuto) return double(settings.cachePoolMb);
  const double paths = double(settings.raysPerFrame) / 4096.0 * double(settings.cacheTau) *
                       double(settings.frameRate) / 15.0;
  const double want =
      std::max(kAutoPoolMinMb, double(pairs) * kAutoPoolPerPairMb * std::max(1.0, paths));
  const double cap = std::min({double(pairs) * double(settings.cacheMemoryMb),
                               0.25 * plannableMemoryBytes() / 1048576.0, 65536.0});
  return std::max(1.0, std::min(want, cap));
}

WorkloadEstimate estimateWorkload(const SceneDesc& scene, const PropagationSettings& settings,
                                  int channels, double durationSeconds) {
  WorkloadEstimate e;
  double order = double(settings.maxOrder);
  // The slowest energy decay: the material (of those the mesh uses) with the smallest mean
  // absorption over the octave bands.
  double alphaMin = 1.0;
  std::vector<char> used(scene.materials.size(), 0);
  for (const auto m : scene.mesh.materialIndex)
    if (size_t(m) < used.size()) used[size_t(m)] = 1;
  for (size_t i = 0; i < scene.materials.size(); ++i) {
    if (!used[i]) continue;
    double mean = 0;
    for (int b = 0; b < kNumBands; ++b) mean += scene.materials[i].absorption[b];
    alphaMin = std::min(alphaMin, mean / kNumBands);
  }
  if (settings.rouletteThreshold > 0.f && alphaMin > 0.0 && alphaMin < 1.0) {
    // (1 - alpha)^n = threshold; survivors add about 10 % (kRouletteSurvival) more bounces.
    const double n = std::log(double(settings.rouletteThreshold)) / std::log1p(-alphaMin);
    order = std::min(order, n * (1.0 + Propagator::kRouletteSurvival));
  } else if (alphaMin >= 1.0) {
    order = 0;
  }
  e.expectedOrder = order;
  // One trace per emitter: every source, or every listener when tracing from the listeners.
  const size_t emitters =
      tracesFromListeners(settings.tracing, scene.sources.size(), scene.listeners.size())
          ? std::max<size_t>(1, scene.listeners.size())
          : scene.sources.size();
  e.segmentsPerFrame = double(settings.raysPerFrame) * (order + 1.0) * double(emitters);
  if (durationSeconds > 0)
    e.segmentsTotal = e.segmentsPerFrame * double(settings.frameRate) * durationSeconds;
  e.expectedSeconds = e.segmentsTotal / kNominalSegmentsPerSecond;
  e.irBytes = double(scene.sources.size()) * channels * double(settings.irLength) *
              double(scene.audio.sampleRate) * kIrBytesPerSample;
  // Every pair's cache grows from one pool: at most the pool, at most every pair's own budget.
  const size_t pairs = scene.sources.size() * scene.listeners.size();
  e.cacheBytes =
      std::min(double(pairs) * double(settings.cacheMemoryMb), cachePoolMbFor(settings, pairs)) *
      1048576.0;
  return e;
}

namespace {

/// The memory check's message: what each part needs, their total and the limit.
std::string memoryNeed(const SceneDesc& scene, const PropagationSettings& settings,
                       const WorkloadEstimate& e, double memoryLimitBytes, bool poolBinds) {
  const std::string irs = "impulse responses of " + g3(settings.irLength) + " s x " +
                          std::to_string(scene.audio.sampleRate) + " Hz x " +
                          std::to_string(scene.sources.size()) + " source(s) x channels (" +
                          g3(e.irBytes / 1e9) + " GB)";
  const std::string caches = poolBinds
                                 ? "a path cache pool of " + g3(e.cacheBytes / 1048576.0) +
                                       " MB (" + g3(e.cacheBytes / 1e9) + " GB)"
                                 : "path caches of " + g3(settings.cacheMemoryMb) + " MB x " +
                                       std::to_string(scene.sources.size()) + " source(s) x " +
                                       std::to_string(scene.listeners.size()) + " listener(s) (" +
                                       g3(e.cacheBytes / 1e9) + " GB)";
  const std::string signals = "dry signals (" + g3(e.signalBytes / 1e9) + " GB)";
  return irs + ", " + caches + " and " + signals + " need about " +
         g3((e.irBytes + e.cacheBytes + e.signalBytes) / 1e9) + " GB, more than the " +
         g3(memoryLimitBytes / 1e9) + " GB available: ";
}

/// Impulse responses, caches and dry signals against the memory available; the message names
/// the largest.
void checkMemory(const SceneDesc& scene, const PropagationSettings& settings,
                 const WorkloadEstimate& e, double memoryLimitBytes) {
  if (e.irBytes + e.cacheBytes + e.signalBytes <= memoryLimitBytes) return;
  const double pairs = double(scene.sources.size()) * double(scene.listeners.size());
  const bool poolBinds =
      cachePoolMbFor(settings, size_t(pairs)) < pairs * double(settings.cacheMemoryMb);
  const std::string need = memoryNeed(scene, settings, e, memoryLimitBytes, poolBinds);
  if (e.signalBytes > e.irBytes && e.signalBytes > e.cacheBytes)
    throw InputError(scene.path, "sources[].signal",
                     need + "use shorter signals, a lower sample_rate or fewer sources");
  if (e.cacheBytes > e.irBytes && poolBinds)
    throw InputError(scene.path, "propagation.cache_pool_mb", need + "lower cache_pool_mb");
  if (e.cacheBytes > e.irBytes)
    throw InputError(scene.path, "propagation.cache_memory_mb",
                     need + "lower cache_memory_mb or the source or listener count");
  throw InputError(scene.path, "propagation.ir_length",
                   need + "lower ir_length, sample_rate or the source count");
}

/// A pool given in MB holds at least the tables every pair's cache starts with (taken from it
/// whatever its budget): below that it would be exceeded from the first frame without a word.
void checkCachePool(const SceneDesc& scene, const PropagationSettings& settings) {
  if (settings.cachePoolMb == kCachePoolAuto) return;
  CachePool start(0);
  const DiffusePathCache one(settings.dpcWeighting, settings.cacheTau, 1.0 / settings.frameRate,
                             size_t(double(settings.cacheMemoryMb) * 1048576.0), &start);
  const double pairs = double(scene.sources.size()) * double(std::max<size_t>(1, scene.listeners.size()));
  const double needMb = pairs * double(start.usedBytes()) / 1048576.0;
  if (double(settings.cachePoolMb) < needMb)
    throw InputError(scene.path, "propagation.cache_pool_mb",
                     g3(settings.cachePoolMb) + " MB is below the " + g3(needMb) + " MB the " +
                         std::to_string(size_t(pairs)) +
                         " source-listener pairs' path caches start with (their first tables)");
}

/// A path cache's tables in its budget (DiffusePathCache::capacityFor), refused here naming
/// the setting rather than inside the engine's first frame.
void checkCacheTables(const SceneDesc& scene, const PropagationSettings& settings) {
  if (settings.estimator != Estimator::kDpc) return;
  try {
    DiffusePathCache::capacityFor(settings.dpcWeighting, settings.cacheTau,
                                  1.0 / settings.frameRate,
                                  size_t(double(settings.cacheMemoryMb) * 1048576.0));
  } catch (const std::invalid_argument& e) {
    const std::string why = e.what();  // "cache_tau: ..." or "cache_memory_mb: ..."
    const size_t colon = why.find(": ");
    throw InputError(scene.path, "propagation." + why.substr(0, colon), why.substr(colon + 2));
  }
  checkCachePool(scene, settings);
}


}  // namespace

std::vector<std::string> checkWorkload(const SceneDesc& scene, const PropagationSettings& settings,
                                       const WorkloadEstimate& e, double memoryLimitBytes) {
  const std::string work = "rays_per_frame " + std::to_string(settings.raysPerFrame) +
                           " x reflection order ~" + g3(e.expectedOrder) + " (max_order " +
                           std::to_string(settings.maxOrder) + ") x " +
                           std::to_string(scene.sources.size()) + " source(s)";
  if (e.segmentsPerFrame > kMaxSegmentsPerFrame)
    throw InputError(scene.path, "propagation.rays_per_frame",
                     work + " = " + g3(e.segmentsPerFrame) + " ray segments per frame, more than " +
                         g3(kMaxSegmentsPerFrame) + ": lower rays_per_frame or max_order");
  if (e.segmentsTotal > kMaxSegmentsTotal)
    throw InputError(scene.path, "propagation.rays_per_frame",
                     work + " x " + g3(e.segmentsTotal / e.segmentsPerFrame) + " frames = " +
                         g3(e.segmentsTotal) + " ray segments, more than " + g3(kMaxSegmentsTotal) +
                         ": lower rays_per_frame, frame_rate or the duration");
  checkCacheTables(scene, settings);
  checkMemory(scene, settings, e, memoryLimitBytes);
  std::vector<std::string> warnings;
  if (e.segmentsTotal > kWarnSegmentsTotal)
    warnings.push_back(scene.path + ": about " + g3(e.segmentsTotal) + " ray segments to trace (" +
                       work + " x " + g3(e.segmentsTotal / e.segmentsPerFrame) +
                       " frames): this render may take about " + g3(e.expectedSeconds / 60.0) +
                       " min (at " + g3(kNominalSegmentsPerSecond) +
                       " segments/s); lower rays_per_frame or max_order to go faster");
  return warnings;
}

}  // namespace dpc
