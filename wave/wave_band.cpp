#include "wave/wave_band.h"

#include <chrono>
#include <cmath>
#include <numbers>

#include "audio/resample.h"
#include "common/butterworth.h"
#include "common/input_error.h"
#include "wave/admittance.h"
#include "wave/fdtd.h"
#include "wave/wave_join.h"

namespace dpc::wave {
namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

/// beta per material from its absorption over the octave bands up to the crossover.
std::vector<float> admittances(const SceneDesc& scene) {
  std::vector<float> beta;
  for (const Material& m : scene.materials)
    beta.push_back(float(admittanceForAbsorption(
        waveBandAbsorption(m.absorption, double(scene.wave.crossover())))));
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

}  // namespace

WaveBand simulateWaveBand(const SceneDesc& scene, const Tracer& tracer, const Geometry& geometry,
                          const WavePoint& source, std::span<const WavePoint> receivers,
                          const WaveBandOptions& options) {
  const double c = scene.propagation.speedOfSound;
  const auto t0 = Clock::now();
  const GridLayout layout = layoutFor(glm::dvec3(geometry.boundsMin()),
                                      glm::dvec3(geometry.boundsMax()), scene.wave.spacing(c),
                                      scene.path);
  std::vector<glm::vec3> seeds{source.position};
  for (const WavePoint& r : receivers) seeds.push_back(r.position);
  const std::vector<float> beta = admittances(scene);
  const WaveGrid grid = buildWaveGrid(layout, tracer, geometry, beta, seeds);
  WaveBand out;
  WaveBandStats& st = out.stats;
  st.layout = layout;
  st.airNodes = grid.airNodes;
  st.boundaryNodes = grid.boundary.size();
  st.stepRate = stepRateFor(layout, c);
  st.steps = size_t(std::ceil(options.seconds * st.stepRate)) + 1;
  st.stateBytes = layout.arraySize() * 3 * sizeof(float) + grid.boundary.size() * 12;
  st.buildSeconds = secondsSince(t0);

  SimulationInput in;
  in.speedOfSound = c;
  in.stepRate = st.stepRate;
  in.source = stencilOrThrow(grid, source, scene.path);
  std::vector<Stencil> at;
  for (const WavePoint& r : receivers) at.push_back(stencilOrThrow(grid, r, scene.path));
  in.receivers = at;
  const std::vector<float> q = pulse(scene.wave.maxFrequencyHz, st.stepRate, st.steps);
  in.signal = q;
  in.steps = st.steps;
  in.progress = options.progress;
  const auto t1 = Clock::now();
  std::vector<std::vector<float>> pressure = simulate(grid, in);
  st.simulateSeconds = secondsSince(t1);
  const size_t samples = size_t(std::llround(options.seconds * options.sampleRate));
  for (auto& p : pressure)
    out.irs.push_back(toAudioRate(std::move(p), st.stepRate, options.sampleRate, samples));
  return out;
}

}  // namespace dpc::wave
