#include "bench/wave_bench.h"

#include <cmath>
#include <cstdio>

#include "engine/embree_tracer.h"
#include "engine/geometry.h"
#include "testing/test_scenes.h"
#include "wave/wave_band.h"

namespace dpc::bench {
namespace {

/// A model link for the rank scaling prediction: 10 Gb/s, 20 us per message (a common
/// cluster Ethernet; InfiniBand is several times faster).
constexpr double kLinkBytesPerSecond = 1.25e9;
constexpr double kLinkLatencySeconds = 20e-6;

Json runOne(double volume, double maxHz, double seconds) {
  const double scale = std::cbrt(volume / (1.6 * 1.3 * 1.0));
  const glm::vec3 size(float(1.6 * scale), float(1.3 * scale), float(1.0 * scale));
  SceneDesc scene = test::makeShoebox(size, Bands(0.1f), 0.1f, size * 0.3f, size * 0.7f);
  scene.wave.enabled = true;
  scene.wave.maxFrequencyHz = float(maxHz);
  const Geometry geometry(scene.mesh, scene.materials, scene.propagation.patchSize);
  const EmbreeTracer tracer(scene.mesh);
  wave::WaveBandOptions opt;
  opt.seconds = seconds;
  const wave::WavePoint from{size * 0.3f, "source"};
  const wave::WavePoint at[] = {{size * 0.7f, "listener"}};
  const wave::WaveBand band = wave::simulateWaveBand(scene, tracer, geometry, from, at, opt);
  const wave::WaveBandStats& s = band.stats;
  const double updates = double(s.layout.arraySize()) * double(s.steps) * double(s.simulations);
  Json j;
  j["volume_m3"] = volume;
  j["max_frequency_hz"] = maxHz;
  j["spacing_m"] = s.layout.spacing.x;
  j["air_nodes"] = s.airNodes;
  j["state_bytes"] = s.stateBytes;
  j["bytes_per_m3"] = double(s.stateBytes) / volume;
  j["step_rate_hz"] = s.stepRate;
  j["steps"] = s.steps;
  j["simulations"] = s.simulations;
  j["grid_s"] = s.buildSeconds;
  j["simulate_s"] = s.simulateSeconds;
  j["node_updates_per_s"] = updates / s.simulateSeconds;
  j["s_per_simulated_s_per_m3"] = s.simulateSeconds / seconds / volume;
  // Slabs along z over R ranks: each step updates 1/R of the nodes and sends one plane of
  // count_x * count_y floats to each of two neighbours.
  const double plane = double(s.layout.dims()[0] * s.layout.dims()[1]) * sizeof(float);
  const double perStep = s.simulateSeconds / double(s.steps * s.simulations);
  Json ranks = Json::array();
  for (int r : {1, 2, 4, 8, 16, 32}) {
    const double comm = r > 1 ? 2.0 * (kLinkLatencySeconds + plane / kLinkBytesPerSecond) : 0.0;
    ranks.push_back({{"ranks", r}, {"predicted_speedup", perStep / (perStep / r + comm)}});
  }
  j["predicted_rank_scaling"] = ranks;
  std::fprintf(stderr, "wave %4.0f Hz %6.0f m^3: %zu nodes, %.1f MB, %.2f s per simulated s "
               "(%.3g node updates/s)\n", maxHz, volume, s.airNodes, double(s.stateBytes) / 1e6,
               s.simulateSeconds / seconds, updates / s.simulateSeconds);
  return j;
}

}  // namespace

int benchWave(const WaveBenchOptions& o) {
  Json runs = Json::array();
  for (double hz : o.frequencies)
    for (double v : o.volumes) runs.push_back(runOne(v, hz, o.seconds));
  Json report;
  report["benchmark"] = "wave";
  report["simulated_seconds"] = o.seconds;
  report["link_model"] = {{"bytes_per_s", kLinkBytesPerSecond},
                          {"latency_s", kLinkLatencySeconds}};
  report["runs"] = runs;
  printReport(report);
  return 0;
}

}  // namespace dpc::bench
