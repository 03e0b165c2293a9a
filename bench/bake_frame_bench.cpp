#include "bench/bake_frame_bench.h"

#include <chrono>
#include <cstdio>
#include <memory>
#include <stdexcept>

#include "bench/sources_bench.h"
#include "engine/baked_field.h"
#include "runtime/propagation_stage.h"

namespace dpc::bench {
namespace {

double since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// A bake of `scene`'s sources at t = 0 on a 1 m grid over the mesh's floor plan at the first
/// listener's height, every response a flat 1e-6 per bin and band (the cost does not depend
/// on the values).
std::shared_ptr<BakedField> syntheticBake(const SceneDesc& scene, const Simulation& sim) {
  auto f = std::make_shared<BakedField>();
  const glm::vec3 lo = sim.geometry().boundsMin(), hi = sim.geometry().boundsMax();
  const float y = scene.listeners.front().position.y;
  for (float x = lo.x + 0.5f; x < hi.x; x += 1.f)
    for (float z = lo.z + 0.5f; z < hi.z; z += 1.f) f->probes.push_back({x, y, z});
  for (const SourceDesc& s : scene.sources) f->sources.push_back(sourcePositionAt(s, 0.0));
  f->bins = sim.result(0).energy.binCount();
  f->late.assign(f->probes.size() * f->sources.size() * f->bins * kNumBands, 1e-6f);
  fillUniformDirections(*f);
  return f;
}

/// Median seconds of traceWorld and prepare over the frames, and the rays and segments of a
/// frame, for one stage.
Json measure(PropagationStage& stage, const SceneDesc& scene, const CommonOptions& c,
             const BakeFrameOptions& o) {
  WorldState world;
  evaluateWorld(scene, 0.0, world);
  std::vector<double> trace, synth;
  for (int f = 0; f < o.warmupFrames + c.frames; ++f) {
    const auto t0 = std::chrono::steady_clock::now();
    stage.traceWorld(world);
    const double t = since(t0);
    const auto t1 = std::chrono::steady_clock::now();
    stage.synthesizeIrs(0);
    if (f < o.warmupFrames) continue;
    trace.push_back(t);
    synth.push_back(since(t1));
  }
  std::vector<double> total(trace.size());
  for (size_t i = 0; i < total.size(); ++i) total[i] = trace[i] + synth[i];
  return {{"propagation_ms", stats(trace, 1e3)},
          {"synthesis_ms", stats(synth, 1e3)},
          {"frame_ms", stats(total, 1e3)},
          {"rays_per_frame", stage.simulation().frameTrace().rays},
          {"segments_per_frame", stage.simulation().frameTrace().segments}};
}

}  // namespace

int benchBakeFrame(const CommonOptions& c, const BakeFrameOptions& o) {
  const SceneDesc base = loadScene(c.scene);
  Json rows = Json::array();
  for (const std::string& name : o.tracing) {
    const std::optional<Tracing> tracing = parseTracing(name);
    if (!tracing) throw std::invalid_argument("--tracing: '" + name + "' is unknown");
    for (const int count : o.counts) {
      SceneDesc scene = withSourceCount(base, count);
      for (SourceDesc& s : scene.sources) s.trajectory.clear();
      scene.listeners.resize(1);
      scene.listeners[0].trajectory.clear();
      scene.audio.output = OutputFormat::kMono;
      scene.propagation = settingsFor(scene, c);
      scene.propagation.tracing = *tracing;
      const auto shared = std::make_shared<const SceneDesc>(scene);
      PropagationStage live(shared, scene.propagation), baked(shared, scene.propagation);
      baked.attachBake(syntheticBake(scene, baked.simulation()));
      Json row = {{"tracing", name}, {"sources", count}};
      row["live"] = measure(live, scene, c, o);
      row["baked"] = measure(baked, scene, c, o);
      row["baked_responses"] = baked.bakedPlayback()->stats().bakedResponses;
      std::fprintf(stderr, "%s, %d sources: frame %.2f ms live, %.2f ms baked\n", name.c_str(),
                   count, double(row["live"]["frame_ms"]["median"]),
                   double(row["baked"]["frame_ms"]["median"]));
      rows.push_back(row);
    }
  }
  printReport({{"benchmark", "bake-frame"},
               {"scene", c.scene},
               {"frames", c.frames},
               {"output", "mono"},
               {"rows", rows}});
  return 0;
}

}  // namespace dpc::bench
