#include "apps/bake/bake_wave.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "apps/bake/progress.h"
#include "common/stop_signals.h"
#include "common/stopwatch.h"
#include "engine/geometry.h"
#include "wave/fdtd.h"
#include "wave/scene_wave.h"

namespace dpc::bake {

void warnWaveProbeSpacing(const SceneDesc& scene, double spacingM) {
  if (!scene.wave.enabled) return;
  const double crossover = scene.wave.crossover();
  const double wavelength = double(scene.propagation.speedOfSound) / crossover;
  if (!(spacingM > kWaveBlendMeasuredSpacing * wavelength)) return;
  std::fprintf(stderr,
               "dpc-bake: warning: --spacing %.2f m is %.2f of the wavelength at the wave band's "
               "crossover (%.0f Hz: %.2f m); the band blended between probes this far apart "
               "loses level (measured up to %.2f of it: 1.4 dB mean error; docs/wave.md, "
               "\"In the bake\")\n",
               spacingM, spacingM / wavelength, crossover, wavelength, kWaveBlendMeasuredSpacing);
}

namespace {

/// One line naming the probes of `source` outside its grid's air, when there are any.
void reportUnreached(const Plan& plan, size_t source, const std::vector<uint8_t>& reached) {
  size_t count = 0, first = reached.size();
  for (size_t p = 0; p < reached.size(); ++p)
    if (!reached[p]) {
      if (count++ == 0) first = p;
    }
  if (count == 0) return;
  const glm::vec3 at = plan.header.probes.positions[first];
  std::fprintf(stderr,
               "dpc-bake: wave band of sources[%zu]: %zu of %zu probes lie in no air its grid "
               "reaches (first: probe %zu at %.3f %.3f %.3f m); they carry no wave band "
               "(wave/reached 0)\n",
               source, count, reached.size(), first, at.x, at.y, at.z);
}

/// The wave band of `source` at every probe: [probes][samples] floats and the reached mask.
/// Progress counts time steps over plan.waveTodo (each simulation has the same number), so
/// the ETA covers the sources still to simulate; this is the k-th of them.
void simulateSource(const Plan& plan, size_t k, Progress& progress, std::vector<float>& band,
                    std::vector<uint8_t>& reached) {
  const size_t source = plan.waveTodo[k];
  const BakeHeader& h = plan.header;
  std::vector<wave::WavePoint> probes;
  for (size_t p = 0; p < h.probes.positions.size(); ++p)
    probes.push_back({h.probes.positions[p], "probe " + std::to_string(p)});
  wave::WaveBandOptions opt;
  opt.seconds = h.settings.irLength;
  opt.sampleRate = h.wave.sampleRate;
  opt.allowUnreached = true;
  opt.progress = [&](size_t done, size_t total) {
    throwIfStopped();  // the control thread between time steps: nothing of this source stored
    progress.stepTo(k * total + done, plan.waveTodo.size() * total);
  };
  const wave::WaveBand w = wave::sceneWaveBandAt(plan.scene, source, probes, 0.0, opt);
  band.assign(probes.size() * h.wave.samples, 0.f);
  for (size_t p = 0; p < probes.size(); ++p)
    std::copy(w.irs[p].begin(), w.irs[p].begin() + std::ptrdiff_t(h.wave.samples),
              band.begin() + std::ptrdiff_t(p * h.wave.samples));
  reached = w.reached;
}

}  // namespace

WaveEstimate estimateWave(const SceneDesc& scene, double irLength) {
  const double c = scene.propagation.speedOfSound;
  const Geometry geometry(scene.mesh, scene.materials, scene.propagation.patchSize, scene.objects);
  const wave::GridLayout layout =
      wave::layoutFor(glm::dvec3(geometry.boundsMin()), glm::dvec3(geometry.boundsMax()),
                      scene.wave.spacing(c), scene.path, scene.wave.spacingField());
  WaveEstimate e;
  e.simulations = scene.sources.size() * wave::simulatedBands(scene.wave.crossover()).size();
  e.count = layout.count;
  e.nodes = layout.arraySize();
  // As simulateWaveBand counts them (wave/wave_band.cpp).
  e.steps = size_t(std::ceil(irLength * wave::stepRateFor(layout, c))) + 1;
  return e;
}

bool bakeWaveBands(const Plan& plan, BakeFile& file, bool quiet, Watchdog* watchdog,
                   WaveBakeStats& stats) {
  if (plan.waveTodo.empty()) return true;
  const auto start = std::chrono::steady_clock::now();
  Progress progress(0, 0, quiet, "wave band steps");
  std::vector<float> band;
  std::vector<uint8_t> reached;
  for (size_t k = 0; k < plan.waveTodo.size(); ++k) {
    const size_t s = plan.waveTodo[k];
    try {
      simulateSource(plan, k, progress, band, reached);
    } catch (const Interrupted&) {
      progress.finish();
      return false;
    }
    reportUnreached(plan, s, reached);
    std::unique_lock<std::mutex> between;
    if (watchdog) between = watchdog->lock();
    file.commitWave(s, band, reached);
    ++stats.sources;
    stats.unreached += size_t(std::count(reached.begin(), reached.end(), uint8_t(0)));
  }
  stats.seconds = secondsSince(start);
  progress.finish();
  return true;
}

}  // namespace dpc::bake
