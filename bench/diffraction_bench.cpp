// `dpc-bench diffraction`: edges found at load time and the direct sound plus diffraction
// per source-listener pair.
#include "bench/diffraction_bench.h"

#include <chrono>
#include <cstdio>
#include <vector>

#include "engine/diffraction.h"
#include "engine/embree_tracer.h"
#include "engine/simulation.h"
#include "scene/trajectory.h"

namespace dpc::bench {
namespace {

using Clock = std::chrono::steady_clock;

/// Per-pair times (microseconds), the edge paths and chains found and what the chains' caps
/// left out (DirectSound::chainsLeftOut), summed over the pairs.
struct PairTimes {
  std::vector<double> micros;
  double paths = 0.0;
  double chainsLeftOut = 0.0;
};

PairTimes timePairs(const SceneDesc& scene, const PropagationSettings& s, const Geometry& geometry,
                    const Tracer& tracer, const EdgeDiffraction& diffraction, int frames) {
  const Propagator propagator(geometry, tracer, s);
  const ListenerDesc& listener = scene.listeners[0];
  const double span = listener.trajectory.empty() ? 20.0 : listener.trajectory.back().timeSeconds;
  PairTimes p;
  for (int f = 0; f < frames; ++f) {
    const double t = span * (f + 0.5) / frames;
    const ListenerSphere sphere{listenerPositionAt(listener, t), listener.radius};
    for (const SourceDesc& source : scene.sources) {
      const glm::vec3 at = sourcePositionAt(source, t);
      const auto a = Clock::now();
      DirectSound d = propagator.directSound(at, sphere);
      p.paths += double(diffraction.apply(tracer, at, sphere, s.speedOfSound,
                                          propagator.airAttenuationPerMetre(), d));
      p.micros.push_back(std::chrono::duration<double, std::micro>(Clock::now() - a).count());
      p.chainsLeftOut += double(d.chainsLeftOut);
    }
  }
  return p;
}

}  // namespace

int benchDiffraction(const CommonOptions& c) {
  const SceneDesc scene = loadScene(c.scene);
  const PropagationSettings s = settingsFor(scene, c);
  const auto t0 = Clock::now();
  const Geometry geometry(scene.mesh, scene.materials, s.patchSize, scene.objects);
  const EmbreeTracer tracer(scene.mesh, scene.objects);
  const auto t1 = Clock::now();
  const EdgeDiffraction diffraction(scene.mesh, scene.objects);
  const auto t2 = Clock::now();
  const PairTimes p = timePairs(scene, s, geometry, tracer, diffraction, std::max(1, c.frames));
  Json j;
  j["benchmark"] = "diffraction";
  j["scene"] = c.scene;
  j["triangles"] = scene.mesh.triangles.size();
  j["candidate_edges"] = diffraction.edges().size();
  j["geometry_build_ms"] = std::chrono::duration<double, std::milli>(t1 - t0).count();
  j["edge_finding_ms"] = std::chrono::duration<double, std::milli>(t2 - t1).count();
  j["pairs_timed"] = p.micros.size();
  j["edge_paths_per_pair_mean"] = p.paths / double(p.micros.size());
  j["chains_left_out_per_pair_mean"] = p.chainsLeftOut / double(p.micros.size());
  j["direct_plus_diffraction_us_per_pair"] = stats(p.micros);
  std::fprintf(stderr, "%zu edges; %.1f edge paths and %.0f us per pair (median)\n",
               diffraction.edges().size(), p.paths / double(p.micros.size()),
               percentile(p.micros, 0.5));
  printReport(j);
  return 0;
}

}  // namespace dpc::bench
