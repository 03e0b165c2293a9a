// `dpc-bench sources`: one child process per (tracing direction, source count).
#include "bench/sources_bench.h"

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <stdexcept>

#include "bench/noise_study.h"
#include "runtime/render_pipeline.h"
#include "scene/enum_names.h"
#include "scene/trajectory.h"

namespace dpc::bench {
namespace {

double wallSeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

/// The radical inverse of i in `base` (Halton's sequence), in [0, 1).
double halton(uint32_t i, uint32_t base) {
  double f = 1.0, r = 0.0;
  for (; i > 0; i /= base) {
    f /= base;
    r += f * double(i % base);
  }
  return r;
}

/// Per sampled source, the converged reference (10 ms bins) at the scene's listener.
std::vector<EnergyResponse> references(const SceneDesc& many, const PropagationSettings& s,
                                       const SourcesOptions& o) {
  std::vector<EnergyResponse> refs;
  PropagationSettings r = s;
  r.raysPerFrame = 4 * s.raysPerFrame;
  r.tracing = Tracing::kFromSources;
  r.seed = s.seed + 0x9e3779b9u;  // streams independent of the measured runs
  const int n = std::min<int>(o.qualitySources, int(many.sources.size()));
  for (int i = 0; i < n; ++i) {
    SceneDesc one = many;
    one.sources = {many.sources[size_t(i)]};
    refs.push_back(referenceResponse(one, r, many.listeners[0].position, o.referenceFrames,
                                     nullptr));
    std::fprintf(stderr, "\rreference %d/%d", i + 1, n);
  }
  std::fprintf(stderr, "\n");
  return refs;
}

/// Totals of one configuration's timed frames.
struct Totals {
  double passWall = 0.0, synthesisWall = 0.0;
  uint64_t segments = 0;
};

void timeFrame(const SceneDesc& scene, PropagationStage& stage, WorldState& world, Totals& t) {
  evaluateWorld(scene, 0.0, world);
  double w0 = wallSeconds();
  stage.traceWorld(world);
  t.passWall += wallSeconds() - w0;
  w0 = wallSeconds();
  stage.synthesizeIrs(0);
  t.synthesisWall += wallSeconds() - w0;
  t.segments += stage.simulation().frameTrace().segments;
}

/// Quality of the sampled sources' energy responses after the warm-up.
Json quality(const Simulation& sim, const std::vector<EnergyResponse>& refs) {
  Json q = Json::array();
  for (size_t i = 0; i < refs.size() && i < sim.sourceCount(); ++i) {
    const EnergyResponse e = noiseBins(sim.result(i).energy);
    Json row;
    row["source"] = i;
    row["energy_error_db"] =
        10.0 * std::log10(double(e.total().sum()) / double(refs[i].total().sum()));
    row["noise"] = relativeError(e, refs[i]);
    q.push_back(row);
  }
  return q;
}

/// Runs one configuration in this process; its report row.
Json runConfiguration(const CommonOptions& c, const SourcesOptions& o, const SceneDesc& many,
                      PropagationSettings s, int count, Tracing tracing,
                      const std::vector<EnergyResponse>& refs) {
  auto scene = std::make_shared<SceneDesc>(many);
  scene->sources.resize(size_t(count));
  s.tracing = tracing;
  Json row;
  row["rendering"] = rendersHybrid(scene->audio, size_t(count)) ? "hybrid" : "per_source";
  PropagationStage stage(scene, s);
  WorldState world;
  stage.reuseSourceIrs(o.keepToleranceDb);
  stage.reuseLateBuses(o.keepToleranceDb);
  if (const HybridSynthesis* h = stage.hybrid()) {
    row["late_buses"] = h->buses();
    row["early_ms"] = 1e3 * h->split().splitSeconds;
  }
  Totals warm, t;
  for (int f = 0; f < o.warmupFrames; ++f) timeFrame(*scene, stage, world, warm);
  row["quality"] = quality(stage.simulation(), refs);
  const HybridCounts before = stage.hybrid() ? stage.hybrid()->counts(0) : HybridCounts{};
  const uint64_t keptBefore = stage.sourceIrCounts(0).kept;
  for (int f = 0; f < c.frames; ++f) timeFrame(*scene, stage, world, t);
  row["source_irs_kept_share"] =
      double(stage.sourceIrCounts(0).kept - keptBefore) / double(c.frames * count);
  if (const HybridSynthesis* h = stage.hybrid())
    row["bus_irs_kept_share"] =
        double(h->counts(0).busesKept - before.busesKept) / double(c.frames * h->buses());
  size_t cacheBytes = 0, exactPaths = 0;
  uint64_t refusals = 0, merged = 0;
  double energy = 0.0, coarseEnergy = 0.0, worstCoarse = 0.0;
  for (int i = 0; i < count; ++i) {
    const Simulation::SourceResult& r = stage.simulation().result(size_t(i));
    cacheBytes += r.cacheBytes;
    exactPaths += r.specularPaths;
    refusals += r.cachePoolRefusals;
    merged += r.cacheMergedEntries;
    const double e = r.energy.total().sum();
    energy += e;
    coarseEnergy += e * r.cacheCoarseEnergyFraction;
    worstCoarse = std::max(worstCoarse, r.cacheCoarseEnergyFraction);
  }
  row["cache_pool_mb"] = double(stage.simulation().result(0).cachePoolBytes) / 1048576.0;
  row["pool_growths_refused"] = refusals;
  row["entries_merged"] = merged;
  row["merged_energy_share"] = energy > 0.0 ? coarseEnergy / energy : 0.0;
  row["merged_energy_share_worst_pair"] = worstCoarse;
  row["pass_ms_per_frame"] = 1e3 * t.passWall / c.frames;
  row["synthesis_ms_per_frame"] = 1e3 * t.synthesisWall / c.frames;
  row["frame_ms"] = 1e3 * (t.passWall + t.synthesisWall) / c.frames;
  row["segments_per_frame"] = double(t.segments) / c.frames;
  row["cache_mb"] = double(cacheBytes) / 1048576.0;
  row["exact_paths"] = exactPaths;
  return row;
}

/// Runs `work` in a forked child and returns what it printed into the pipe, with the child's
/// peak resident memory in *peakMb. The parent itself never starts the tracing threads (TBB is
/// not fork-safe), so every configuration starts from a fresh process image.
template <class Work>
std::string inChild(const std::string& what, Work&& work, double* peakMb) {
  int fd[2];
  if (pipe(fd) != 0) throw std::runtime_error("dpc-bench sources: pipe failed");
  std::fflush(nullptr);
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("dpc-bench sources: fork failed");
  if (pid == 0) {
    close(fd[0]);
    const std::string text = work();
    const bool ok = write(fd[1], text.data(), text.size()) == ssize_t(text.size());
    _exit(ok ? 0 : 1);
  }
  close(fd[1]);
  std::string text;
  char buf[4096];
  for (ssize_t n; (n = read(fd[0], buf, sizeof buf)) > 0;) text.append(buf, size_t(n));
  close(fd[0]);
  int status = 0;
  rusage usage{};
  wait4(pid, &status, 0, &usage);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
    throw std::runtime_error("dpc-bench sources: " + what + " failed");
  if (peakMb) *peakMb = double(usage.ru_maxrss) / 1024.0;  // Linux: kilobytes
  return text;
}

/// The references computed in a child, as JSON (per source, per 10 ms bin, 8 bands).
std::vector<EnergyResponse> referencesInChild(const SceneDesc& many, const PropagationSettings& s,
                                              const SourcesOptions& o) {
  const std::string text = inChild("the references", [&] {
    Json j = Json::array();
    for (const EnergyResponse& e : references(many, s, o)) {
      Json bins = Json::array();
      for (const Bands& b : e.bins()) bins.push_back(std::vector<float>(b.v.begin(), b.v.end()));
      j.push_back(bins);
    }
    return j.dump();
  }, nullptr);
  std::vector<EnergyResponse> refs;
  for (const Json& bins : Json::parse(text)) {
    EnergyResponse e(double(bins.size()) * kNoiseBinSeconds, kNoiseBinSeconds);
    for (size_t k = 0; k < bins.size() && k < e.binCount(); ++k)
      for (int i = 0; i < kNumBands; ++i) e.bins()[k][i] = bins[k][size_t(i)].get<float>();
    refs.push_back(std::move(e));
  }
  return refs;
}

void printLine(const std::string& tracing, int count, const Json& row, const Json& one) {
  double worstDb = 0.0, worstNoise = 0.0;
  for (const Json& q : row["quality"]) {
    worstDb = std::max(worstDb, std::abs(q["energy_error_db"].get<double>()));
    worstNoise = std::max(worstNoise, q["noise"].get<double>());
  }
  std::fprintf(stderr,
               "%-14s %3d sources: pass %.1f ms, synthesis %.1f ms, frame x%.2f of one source, "
               "peak RSS %.0f MB; worst sampled source %.2f dB, noise %.3f; %.1f %% of the "
               "energy merged (pool growths refused %llu)\n",
               tracing.c_str(), count, row["pass_ms_per_frame"].get<double>(),
               row["synthesis_ms_per_frame"].get<double>(),
               row["frame_ms"].get<double>() / one["frame_ms"].get<double>(),
               row["peak_rss_mb"].get<double>(), worstDb, worstNoise,
               100.0 * row["merged_energy_share"].get<double>(),
               (unsigned long long)row["pool_growths_refused"].get<uint64_t>());
}

}  // namespace

SceneDesc withSourceCount(const SceneDesc& scene, int count) {
  SceneDesc many = scene;
  glm::vec3 lo(INFINITY), hi(-INFINITY);
  for (const glm::vec3& v : scene.mesh.vertices) {
    lo = glm::min(lo, v);
    hi = glm::max(hi, v);
  }
  const glm::vec3 margin = 0.15f * (hi - lo);
  lo += margin;
  hi -= margin;
  for (uint32_t i = uint32_t(scene.sources.size()); i < uint32_t(count); ++i) {
    SourceDesc s = scene.sources.front();
    s.name = "source " + std::to_string(i);
    s.position = lo + (hi - lo) * glm::vec3(halton(i + 1, 2), halton(i + 1, 3), halton(i + 1, 5));
    s.trajectory.clear();
    many.sources.push_back(s);
  }
  many.sources.resize(size_t(count));
  return many;
}

int benchSources(const CommonOptions& c, const SourcesOptions& o) {
  const SceneDesc scene = loadScene(c.scene);
  const int maxCount = *std::max_element(o.counts.begin(), o.counts.end());
  SceneDesc many = withSourceCount(scene, maxCount);
  const std::optional<Rendering> rendering = parseRendering(o.rendering);
  if (!rendering) throw std::invalid_argument("--rendering: '" + o.rendering + "' is unknown");
  many.audio.rendering = *rendering;
  for (SourceDesc& s : many.sources) s.trajectory.clear();
  many.listeners.resize(1);
  many.listeners[0].trajectory.clear();
  const PropagationSettings s = settingsFor(many, c);
  const std::vector<EnergyResponse> refs = referencesInChild(many, s, o);
  Json j;
  j["scene"] = c.scene;
  j["rays_per_frame"] = s.raysPerFrame;
  j["frames"] = c.frames;
  j["warmup_frames"] = o.warmupFrames;
  j["machine"] = "shared 2-core machine: ratios within one run";
  j["rendering"] = o.rendering;
  for (const std::string& name : o.tracing) {
    const std::optional<Tracing> tracing = parseTracing(name);
    if (!tracing) throw std::invalid_argument("--tracing: '" + name + "' is not a direction");
    Json rows = Json::array();
    for (int count : o.counts) {
      if (*tracing == Tracing::kFromSources && count > o.maxFromSources) continue;
      double peakMb = 0.0;
      Json row = Json::parse(inChild(
          std::to_string(count) + " sources",
          [&] { return runConfiguration(c, o, many, s, count, *tracing, refs).dump(); },
          &peakMb));
      row["peak_rss_mb"] = peakMb;
      row["sources"] = count;
      rows.push_back(row);
      printLine(name, count, row, rows.front());
    }
    j[name] = rows;
  }
  j["note"] =
      "pass: tracing + every pair's cache (Simulation::runFrame); synthesis: every source's IR "
      "for the listener, or in hybrid rendering every source's early part and every late bus "
      "(PropagationStage::prepare); quality after warmup_frames: energy error "
      "(dB) and relative RMS noise per 10 ms bin and band against path tracing with 4x rays "
      "over reference_frames frames; peak RSS of the configuration's own process";
  j["reference_frames"] = o.referenceFrames;
  j["max_from_sources"] = o.maxFromSources;
  j["keep_tolerance_db"] = o.keepToleranceDb;
  printReport(j);
  return 0;
}

}  // namespace dpc::bench
