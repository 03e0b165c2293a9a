#include "bake/probe_bake.h"

#include <chrono>
#include <cmath>
#include <limits>

#include "analysis/expected_band_analysis.h"
#include "analysis/room_parameters.h"
#include "analysis/speech_transmission.h"
#include "common/random.h"
#include "engine/simulation.h"
#include "engine/specular_paths.h"

namespace dpc::bake {
namespace {

/// Per band b, per bin k: energy[b][k] (doubles).
using BandSeries = std::array<std::vector<double>, kNumBands>;

/// Two-sided 95 % Student t quantile for dof degrees of freedom (1..10; beyond, 10's value
/// errs on the wide side).
double studentT95(int dof) {
  static constexpr double t[] = {12.706, 4.303, 3.182, 2.776, 2.571,
                                 2.447,  2.365, 2.306, 2.262, 2.228};
  return t[std::clamp(dof, 1, 10) - 1];
}

/// The parameters of one response (bands, then broadband) in kParameterNames order, and STI;
/// onsetSeconds: the direct sound's arrival (onsetSecondsOf), where C80 and D50 start. The
/// broadband response weighs each band by its share of a white spectrum at sampleRate
/// (whiteSpectrumShares): the energy the IR played from the bake carries.
std::vector<double> parametersOf(const BandSeries& e, double bin, double onsetSeconds,
                                 double sampleRate) {
  const std::array<double, kNumBands> share = whiteSpectrumShares(sampleRate);
  std::vector<double> out;
  std::vector<double> sum(e[0].size(), 0.0);
  auto add = [&](const audio::RoomParameters& p) {
    for (double v : {p.t20, p.t30, p.edt, p.c50, p.c80, p.d50, audio::strengthDb(p.energy)})
      out.push_back(v);
  };
  for (int b = 0; b < kNumBands; ++b) {
    add(audio::analyzeEnergyDecay(e[size_t(b)].data(), e[size_t(b)].size(), bin, onsetSeconds));
    for (size_t k = 0; k < sum.size(); ++k) sum[k] += share[size_t(b)] * e[size_t(b)][k];
  }
  add(audio::analyzeEnergyDecay(sum.data(), sum.size(), bin, onsetSeconds));
  std::array<std::span<const double>, audio::kStiBands> sti;
  for (int k = 0; k < audio::kStiBands; ++k) sti[size_t(k)] = e[size_t(audio::kStiFirstBand + k)];
  out.push_back(audio::speechTransmissionIndex(sti, bin));
  return out;
}

/// Bin width of the SH energy, seconds.
constexpr double kShBinSeconds = double(kDirectionalBinFactor) * Simulation::kEnergyBinSeconds;

/// Accumulates one frame's response of a source into `series`, scaled by `weight`.
void accumulate(const EnergyResponse& r, double weight, BandSeries& series) {
  for (size_t k = 0; k < r.binCount(); ++k)
    for (int b = 0; b < kNumBands; ++b) series[size_t(b)][k] += weight * r.bins()[k][b];
}

void addDirect(const DirectSound& d, double bin, BandSeries& series) {
  if (!d.visible) return;
  const size_t k = size_t(d.delaySeconds / bin);
  if (k >= series[0].size()) return;
  for (int b = 0; b < kNumBands; ++b) series[size_t(b)][k] += d.intensity[b];
}

/// Adds `weight` times an SH energy response into sh ([directional bin][channel][band]).
void accumulateSh(const ShEnergyResponse& r, double weight, std::vector<float>& sh) {
  const std::span<const float> d = r.data();
  for (size_t i = 0; i < d.size() && i < sh.size(); ++i) sh[i] += float(weight) * d[i];
}

/// The direct sound of a source at its direction, as the simulation adds its arrivals.
void addDirectSh(const DirectSound& d, double irLength, std::vector<float>& sh) {
  if (!d.visible) return;
  ShEnergyResponse one(kShOrder, irLength, kShBinSeconds);
  one.add(d.delaySeconds, d.intensity, d.direction);
  accumulateSh(one, 1.0, sh);
}

/// One source's sums over a probe's frames.
struct SourceSums {
  std::vector<BandSeries> groups;  ///< [group]: the group's mean whole response
  std::vector<float> sh;           ///< [directional bin][channel][band]: mean SH energy
  BandSeries exact;                ///< the exact early paths' part of the mean response
  std::vector<float> exactSh;      ///< the exact early paths' part of sh
};

/// Adds the exact early paths' response of one frame, scaled by `weight`, to the source's
/// exact-path sums (what playback takes out of the stored response: it adds the live paths).
void accumulateExact(const std::vector<SpecularPath>& paths, const EnergyResponse& like,
                     double irLength, double weight, SourceSums& sums) {
  EnergyResponse exact = like;
  exact.clear();
  ShEnergyResponse exactSh(kShOrder, irLength, kShBinSeconds);
  addSpecularPaths(paths, exact, &exactSh);
  accumulate(exact, weight, sums.exact);
  accumulateSh(exactSh, weight, sums.exactSh);
}

/// Adds source s's whole response of the frame just run: the estimator's plus the exact early
/// paths, which the estimators leave out (engine/specular_paths.h), scaled by `weight` into
/// the group's series and by `dirWeight` into the SH energy; the paths alone, scaled by
/// `dirWeight` (the mean over all frames), into the exact-path sums.
void accumulateFrame(const Simulation& sim, size_t s, size_t group, double weight,
                     double dirWeight, double irLength, SourceSums& sums) {
  const std::vector<SpecularPath>& paths = sim.specularPaths(s);
  if (paths.empty()) {
    accumulate(sim.result(s).energy, weight, sums.groups[group]);
    accumulateSh(sim.shEnergy(s), dirWeight, sums.sh);
    return;
  }
  EnergyResponse whole = sim.result(s).energy;
  ShEnergyResponse wholeSh = sim.shEnergy(s);
  addSpecularPaths(paths, whole, &wholeSh);
  accumulate(whole, weight, sums.groups[group]);
  accumulateSh(wholeSh, dirWeight, sums.sh);
  accumulateExact(paths, sim.result(s).energy, irLength, dirWeight, sums);
}

/// Source s's exact early paths of the last frame (shortest first) into the result's rows.
void storeEarly(const std::vector<SpecularPath>& paths, size_t s, ProbeResult& out) {
  const size_t n = std::min(paths.size(), kEarlyPaths);
  out.earlyCount[s] = float(n);
  out.earlyFound[s] = float(paths.size());
  float* row = out.early.data() + s * kEarlyPaths * kEarlyPathFloats;
  for (size_t i = 0; i < n; ++i, row += kEarlyPathFloats) {
    const SpecularPath& p = paths[i];
    row[0] = float(p.delaySeconds);
    for (int b = 0; b < kNumBands; ++b) row[1 + b] = p.intensity[b];
    for (int c = 0; c < 3; ++c) row[1 + kNumBands + c] = p.direction[c];
  }
}

/// Mean and 95 % half-width over the groups' parameter vectors, into the result's slots.
void summarise(const std::vector<double>& mean, const std::vector<std::vector<double>>& groups,
               size_t source, ProbeResult& out) {
  const size_t np = size_t(kParameterRows * kParameters);
  const double g = double(groups.size());
  for (size_t i = 0; i < mean.size(); ++i) {
    double m = 0.0, s2 = 0.0;
    for (const auto& v : groups) m += v[i] / g;
    for (const auto& v : groups) s2 += (v[i] - m) * (v[i] - m) / (g - 1.0);
    const double ci = studentT95(int(g) - 1) * std::sqrt(s2 / g);
    if (i < np) {
      out.parameters[source * np + i] = float(mean[i]);
      out.parametersCi[source * np + i] = std::isfinite(ci) ? float(ci) : NAN;
    } else {
      out.sti[source] = float(mean[i]);
      out.stiCi[source] = std::isfinite(ci) ? float(ci) : NAN;
    }
  }
}

/// The propagation settings of a bake's probe `probe` (its seed: the scene's combined with it).
PropagationSettings probeSettings(const SceneDesc& scene, const BakeSettings& s, size_t probe) {
  PropagationSettings p = scene.propagation;
  p.estimator = Estimator::kPathTracing;
  p.raysPerFrame = s.rays;
  p.threads = s.threads;
  p.irLength = float(s.irLength);
  p.seed = hashCombine(scene.propagation.seed, probe);
  return p;
}

ProbeResult allocate(const ProbeShape& shape) {
  ProbeResult r;
  r.energy.assign(shape.energyFloats(), 0.f);
  r.sh.assign(shape.shFloats(), 0.f);
  r.directDelay.assign(shape.sources, 0.f);
  r.directEnergy.assign(shape.sources * kNumBands, 0.f);
  r.directDirection.assign(shape.sources * 3, 0.f);
  r.parameters.assign(shape.parameterFloats(), 0.f);
  r.parametersCi.assign(shape.parameterFloats(), 0.f);
  r.sti.assign(shape.sources, 0.f);
  r.stiCi.assign(shape.sources, 0.f);
  r.earlyCount.assign(shape.sources, 0.f);
  r.earlyFound.assign(shape.sources, 0.f);
  r.early.assign(shape.earlyFloats(), 0.f);
  r.earlyEnergy.assign(shape.energyFloats(), 0.f);
  r.earlySh.assign(shape.shFloats(), 0.f);
  return r;
}

/// The source's mean response (with the direct sound) into the result's energy rows.
void storeSource(const BandSeries& mean, const DirectSound& d, size_t s, const ProbeShape& shape,
                 ProbeResult& out) {
  for (size_t k = 0; k < shape.bins; ++k)
    for (int b = 0; b < kNumBands; ++b)
      out.energy[(s * shape.bins + k) * kNumBands + size_t(b)] = float(mean[size_t(b)][k]);
  out.directDelay[s] = d.visible ? d.delaySeconds : 0.f;
  for (int b = 0; b < kNumBands; ++b)
    out.directEnergy[s * kNumBands + size_t(b)] = d.visible ? d.intensity[b] : 0.f;
  for (int c = 0; c < 3; ++c) out.directDirection[s * 3 + size_t(c)] = d.visible ? d.direction[c] : 0.f;
}

/// The source's SH energy and the exact paths' parts of both responses into the result's rows.
void storeSums(const SourceSums& sums, size_t s, const ProbeShape& shape, ProbeResult& out) {
  const size_t n = sums.sh.size();
  std::copy(sums.sh.begin(), sums.sh.end(), out.sh.begin() + std::ptrdiff_t(s * n));
  std::copy(sums.exactSh.begin(), sums.exactSh.end(), out.earlySh.begin() + std::ptrdiff_t(s * n));
  for (size_t k = 0; k < shape.bins; ++k)
    for (int b = 0; b < kNumBands; ++b)
      out.earlyEnergy[(s * shape.bins + k) * kNumBands + size_t(b)] =
          float(sums.exact[size_t(b)][k]);
}

/// One source's groups of frames into the result: the mean response with the direct sound, its
/// parameters and their confidence half-widths from the groups.
void finishSource(std::vector<BandSeries>& groups, const DirectSound& direct, size_t s,
                  const ProbeShape& shape, double sampleRate, ProbeResult& out) {
  const double bin = Simulation::kEnergyBinSeconds;
  BandSeries mean;
  for (auto& band : mean) band.assign(shape.bins, 0.0);
  std::vector<std::vector<double>> groupParameters;
  for (auto& g : groups) {
    for (int b = 0; b < kNumBands; ++b)
      for (size_t k = 0; k < shape.bins; ++k)
        mean[size_t(b)][k] += g[size_t(b)][k] / double(groups.size());
    addDirect(direct, bin, g);
    groupParameters.push_back(parametersOf(g, bin, onsetSecondsOf(direct), sampleRate));
  }
  addDirect(direct, bin, mean);
  storeSource(mean, direct, s, shape, out);
  summarise(parametersOf(mean, bin, onsetSecondsOf(direct), sampleRate), groupParameters, s, out);
}

}  // namespace

size_t responseBins(double irLength) {
  return EnergyResponse(irLength, Simulation::kEnergyBinSeconds).binCount();
}

ProbeShape probeShape(const SceneDesc& scene, const BakeSettings& settings) {
  return {scene.sources.size(), responseBins(settings.irLength)};
}

ProbeBaker::ProbeBaker(const SceneDesc& scene, const BakeSettings& settings)
    : scene_(scene),
      settings_(settings),
      sim_(std::make_unique<Simulation>(scene, probeSettings(scene, settings, 0))) {
  sim_->enableShEnergy(kShOrder, kShBinSeconds);
}

ProbeBaker::~ProbeBaker() = default;

ProbeResult bakeProbe(const SceneDesc& scene, const BakeSettings& settings, size_t probe,
                      const glm::vec3& position) {
  return ProbeBaker(scene, settings).bake(probe, position);
}

ProbeResult ProbeBaker::bake(size_t probe, const glm::vec3& position) {
  const ProbeShape shape = probeShape(scene_, settings_);
  Simulation& sim = *sim_;
  sim.restart(hashCombine(scene_.propagation.seed, probe));
  const size_t groups = size_t(settings_.subStreams);
  const size_t perGroup = size_t(settings_.frames) / groups;
  std::vector<SourceSums> sums(shape.sources);
  for (SourceSums& src : sums) {
    src.groups.resize(groups);
    for (auto& g : src.groups)
      for (auto& band : g) band.assign(shape.bins, 0.0);
    for (auto& band : src.exact) band.assign(shape.bins, 0.0);
    src.sh.assign(shape.shFloats() / shape.sources, 0.f);
    src.exactSh.assign(src.sh.size(), 0.f);
  }
  for (size_t f = 0; f < groups * perGroup; ++f) {
    sim.runFrame(position);
    for (size_t s = 0; s < shape.sources; ++s)
      accumulateFrame(sim, s, f / perGroup, 1.0 / double(perGroup),
                      1.0 / double(groups * perGroup), settings_.irLength, sums[s]);
  }
  ProbeResult out = allocate(shape);
  for (size_t s = 0; s < shape.sources; ++s) {
    addDirectSh(sim.result(s).direct, settings_.irLength, sums[s].sh);
    storeEarly(sim.specularPaths(s), s, out);
    storeSums(sums[s], s, shape, out);
    // Broadband at the default scene rate, as dpc-analyze reads a response (a bake holds no
    // sample rate: it plays at any).
    finishSource(sums[s].groups, sim.result(s).direct, s, shape, double(AudioSettings{}.sampleRate),
                 out);
  }
  return out;
}

double ProbeBaker::timeFrame(const glm::vec3& position) {
  sim_->restart(scene_.propagation.seed);
  const auto start = std::chrono::steady_clock::now();
  sim_->runFrame(position);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  maxOrderShare_ = 0.0;
  for (size_t s = 0; s < scene_.sources.size(); ++s)
    maxOrderShare_ = std::max(maxOrderShare_, sim_->result(s).trace.maxOrderShare());
  return seconds;
}

std::vector<float> pack(const ProbeResult& r) {
  std::vector<float> out;
  for (const auto* v : {&r.energy, &r.sh, &r.directDelay, &r.directEnergy, &r.directDirection,
                        &r.parameters, &r.parametersCi, &r.sti, &r.stiCi, &r.earlyCount,
                        &r.earlyFound, &r.early, &r.earlyEnergy, &r.earlySh})
    out.insert(out.end(), v->begin(), v->end());
  return out;
}

ProbeResult unpack(const std::vector<float>& packed, const ProbeShape& shape) {
  ProbeResult r = allocate(shape);
  auto it = packed.begin();
  for (auto* v : {&r.energy, &r.sh, &r.directDelay, &r.directEnergy, &r.directDirection,
                  &r.parameters, &r.parametersCi, &r.sti, &r.stiCi, &r.earlyCount, &r.earlyFound,
                  &r.early, &r.earlyEnergy, &r.earlySh}) {
    std::copy(it, it + std::ptrdiff_t(v->size()), v->begin());
    it += std::ptrdiff_t(v->size());
  }
  return r;
}

}  // namespace dpc::bake
