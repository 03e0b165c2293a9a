#include "wave/wave_band.h"

#include <chrono>
#include <cmath>
#include <numbers>

#include "audio/resample.h"
#include "common/butterworth.h"
#include "common/input_error.h"
#include "common/stopwatch.h"
#include "wave/admittance.h"
#include "wave/fdtd.h"
#include "wave/wave_join.h"

namespace dpc::wave {
namespace {

using Clock = std::chrono::steady_clock;

/// beta per material from its absorption in octave band `band`.
std::vector<float> admittances(const SceneDesc& scene, int band) {
  std::vector<float> beta;
  for (const Material& m : scene.materials)
    beta.push_back(float(admittanceForAbsorption(m.absorption[band])));
  return beta;
}

/// The unit-area band-limited pulse as volume acceleration per step (m^3/s^2): a unit impulse
/// of height stepRate through the low-pass, rung out to 1e-7 of its peak or `steps`.
std::vector<float> pulse(double maxFrequencyHz, int stepRate, size_t steps) {
  const size_t length = std::min(steps, size_t(std::ceil(40.0 * stepRate / maxFrequencyHz)));
  std::vector<float> q(length, 0.f);
  if (q.empty()) return q;
  q[0] = float(stepRate);
  Butterworth::design(Butterworth::Kind::kLowPass, kPulseOrder, maxFrequencyHz, stepRate).run(q);
  return q;
}

Stencil stencilOrThrow(const WaveGrid& grid, const WavePoint& p, const std::string& file) {
  const auto s = stencilAt(grid, p.position);
  if (!s)
    throw InputError(file, p.field,
                     "lies in no air the wave grid reaches (inside a wall, outside the mesh's "
                     "bounds, or in a closed space the source cannot reach)");
  return *s;
}

/// The receiver pressure at `stepRate` as an IR at `sampleRate`: resampled, scaled to the
/// discrete IR's convention (1 / sampleRate) and to the energy response's scale (sqrt(4 pi):
/// the free field's 1 / (4 pi r) becomes 1 / (sqrt(4 pi) r)), the offset below kWaveDcHz
/// removed.
std::vector<float> toAudioRate(std::vector<float> pressure, int stepRate, int sampleRate,
                               size_t samples) {
  audio::AudioData in;
  in.sampleRate = stepRate;
  in.channels.push_back(std::move(pressure));
  std::vector<float> ir = std::move(audio::resample(in, sampleRate).channels.front());
  ir.resize(samples, 0.f);
  const double scale = std::sqrt(4.0 * std::numbers::pi) / double(sampleRate);
  for (float& v : ir) v = float(double(v) * scale);
  Butterworth::design(Butterworth::Kind::kHighPass, 2, kWaveDcHz, sampleRate).run(ir);
  return ir;
}

/// The simulation's input for `grid` (its stencils, pulse and length in `st`).
struct Run {
  SimulationInput in;
  std::vector<Stencil> receivers;  ///< those in the air
  std::vector<size_t> index;       ///< per entry of receivers: the receiver it is
  std::vector<float> pulse;
};

void prepare(Run& run, const SceneDesc& scene, const WaveGrid& grid, const WavePoint& source,
             std::span<const WavePoint> receivers, bool allowUnreached, const WaveBandStats& st) {
  run.in.speedOfSound = scene.propagation.speedOfSound;
  run.in.stepRate = st.stepRate;
  run.in.source = stencilOrThrow(grid, source, scene.path);
  for (size_t r = 0; r < receivers.size(); ++r) {
    const auto s = stencilAt(grid, receivers[r].position);
    if (!s && allowUnreached) continue;
    if (!s)
      throw InputError(scene.path, receivers[r].field,
                       "lies in no air the wave grid reaches from " + source.field +
                           " (one of them is inside a wall or a solid, outside the mesh, or in "
                           "a closed space apart from the other)");
    run.receivers.push_back(*s);
    run.index.push_back(r);
  }
  run.in.receivers = run.receivers;
  run.pulse = pulse(scene.wave.maxFrequencyHz, st.stepRate, st.steps);
  run.in.signal = run.pulse;
  run.in.steps = st.steps;
}

/// One simulation per octave band up to the crossover, each with that band's admittances,
/// split at the band edges and summed: the IR per receiver at the audio rate.
std::vector<std::vector<float>> simulateBands(const SceneDesc& scene, WaveGrid& grid,
                                              const WavePoint& source,
                                              std::span<const WavePoint> receivers,
                                              const WaveBandOptions& options,
                                              const WaveBandStats& st) {
  Run run;
  prepare(run, scene, grid, source, receivers, options.allowUnreached, st);
  run.in.link = options.link;
  const std::vector<int> bands = simulatedBands(scene.wave.crossover());
  const std::vector<double> edges = bandEdges(bands);
  const size_t samples = size_t(std::llround(options.seconds * options.sampleRate));
  std::vector<std::vector<float>> irs(receivers.size(), std::vector<float>(samples, 0.f));
  if (run.receivers.empty()) return irs;  // every receiver out of the air: nothing to hear
  for (size_t k = 0; k < bands.size(); ++k) {
    setAdmittances(grid, admittances(scene, bands[k]));
    if (options.progress)
      run.in.progress = [&, k](size_t done, size_t total) {
        options.progress(k * total + done, bands.size() * total);
      };
    std::vector<std::vector<float>> pressure = simulate(grid, run.in);
    for (size_t r = 0; r < pressure.size(); ++r) {
      std::vector<float> ir =
          toAudioRate(std::move(pressure[r]), st.stepRate, options.sampleRate, samples);
      splitBand(ir, k, edges, options.sampleRate);
      std::vector<float>& out = irs[run.index[r]];
      for (size_t i = 0; i < samples; ++i) out[i] += ir[i];
    }
  }
  return irs;
}

}  // namespace

WaveBand simulateWaveBand(const SceneDesc& scene, const Tracer& tracer, const Geometry& geometry,
                          const WavePoint& source, std::span<const WavePoint> receivers,
                          const WaveBandOptions& options) {
  const double c = scene.propagation.speedOfSound;
  const auto t0 = Clock::now();
  const GridLayout layout = layoutFor(glm::dvec3(geometry.boundsMin()),
                                      glm::dvec3(geometry.boundsMax()), scene.wave.spacing(c),
                                      scene.path, scene.wave.spacingField());
  // The air is what the source reaches: a receiver elsewhere (inside a solid, outside a
  // closed mesh, in a room the source cannot reach) is refused, or skipped with
  // allowUnreached, rather than simulated in air of its own, where it would hear nothing.
  const std::vector<glm::vec3> seeds{source.position};
  WaveGrid grid = buildWaveGrid(layout, tracer, geometry, seeds);
  WaveBand out;
  WaveBandStats& st = out.stats;
  st.layout = layout;
  st.airNodes = grid.airNodes;
  st.boundaryNodes = grid.boundary.size();
  st.stepRate = stepRateFor(layout, c);
  st.steps = size_t(std::ceil(options.seconds * st.stepRate)) + 1;
  // This process's: the air mask and boundary list whole, the pressure of its slab.
  const Slab slab = options.link ? slabOf(layout, options.link->rank(), options.link->size())
                                 : slabOf(layout, 0, 1);
  st.stateBytes = layout.arraySize() * sizeof(float) +
                  2 * pressureFloats(layout, slab) * sizeof(float) +
                  grid.boundary.size() * sizeof(BoundaryNode);
  st.simulations = simulatedBands(scene.wave.crossover()).size();
  st.processes = options.link ? options.link->size() : 1;
  st.buildSeconds = secondsSince(t0);
  const auto t1 = Clock::now();
  out.irs = simulateBands(scene, grid, source, receivers, options, st);
  out.reached.resize(receivers.size());
  for (size_t r = 0; r < receivers.size(); ++r)
    out.reached[r] = stencilAt(grid, receivers[r].position) ? 1 : 0;
  st.simulateSeconds = secondsSince(t1);
  return out;
}

}  // namespace dpc::wave

