// `dpc-bench noise`: DPC weightings and path tracing at several ray counts against converged
// references, by delay range, and the rays path tracing needs for the DPC's noise.
#include "bench/noise_bench.h"

#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <numeric>
#include <string>
#include <utility>

#include "bench/noise_study.h"
#include "engine/geometry.h"
#include "engine/room_volume.h"
#include "scene/trajectory.h"

namespace dpc::bench {
namespace {

using Ranges = std::vector<std::pair<double, double>>;
/// (ray multiplier, error corrected for the reference's own error) per path-tracing run.
using ErrorCurve = std::vector<std::pair<double, double>>;

/// Order ranges reported separately, measured as delay ranges (mean reflection rate of the
/// room, bench/noise_study.h).
const std::vector<std::pair<int, int>> kOrderRanges = {{1, 3}, {4, 10}, {11, 50}, {51, 200}};

std::string rangeName(size_t r) {
  return std::to_string(kOrderRanges[r].first) + "-" + std::to_string(kOrderRanges[r].second);
}

/// The reference's own error adds in quadrature to an estimator's error against it.
double correctedBy(double e, double r) {
  return std::sqrt(std::max(0.0, e * e - r * r));
}

/// Listener path for the noise study: the scene's trajectory (or +x from its position)
/// walked at `speed` m/s, sampled at frame f of a rate of `frameRate`.
std::function<glm::vec3(int)> walker(const SceneDesc& scene, double speed, double frameRate) {
  std::vector<glm::vec3> pts;
  for (const Keyframe& k : scene.listeners[0].trajectory) pts.push_back(k.position);
  if (pts.size() < 2) {
    const glm::vec3 p = listenerPositionAt(scene.listeners[0], 0.0);
    pts = {p, p + glm::vec3(100.f, 0.f, 0.f)};
  }
  return [pts, speed, frameRate](int f) {
    double d = speed * f / frameRate;
    for (size_t i = 0; i + 1 < pts.size(); ++i) {
      const double len = glm::length(pts[i + 1] - pts[i]);
      if (d <= len || i + 2 == pts.size())
        return pts[i] + (pts[i + 1] - pts[i]) * float(std::min(1.0, d / std::max(len, 1e-9)));
      d -= len;
    }
    return pts.back();
  };
}

/// Everything the measurements share: the scene, settings, listener path and references.
struct Study {
  SceneDesc scene;
  PropagationSettings s;
  std::function<glm::vec3(int)> at;
  int warmup = 0, frames = 0;
  bool walking = false;
  Ranges delayRanges;
  std::vector<EnergyResponse> refs;  ///< per frame when walking, else one
  double refError = 0.0;             ///< the references' mean own relative error
  std::vector<double> refRangeErrors;

  const EnergyResponse& ref(int f) const { return refs[walking ? size_t(f) : 0]; }
  double corrected(double e) const { return correctedBy(e, refError); }
  NoiseMetrics measure(const PropagationSettings& p, int warm, int n, const Ranges& r) const {
    return measureNoise(
        scene, p, warm, n, at, [this](int f) -> const EnergyResponse& { return ref(f); }, 0,
        nullptr, r);
  }
};

Ranges delayRangesOf(const Study& st) {
  const Geometry geometry(st.scene.mesh, st.scene.materials, st.s.patchSize, st.scene.objects);
  const double volume = roomVolume(st.scene.mesh);  // the room's, not its bounding box's
  const double direct =
      glm::length(st.scene.sources[0].position - st.at(0)) / double(st.s.speedOfSound);
  Ranges ranges;
  for (auto [d0, d1] : kOrderRanges)
    ranges.push_back(
        delayRangeOfOrders(d0, d1, volume, geometry.surfaceArea(), st.s.speedOfSound, direct));
  return ranges;
}

/// References: converged plain path tracing at each frame's position (one if static).
void computeReferences(Study& st, int referenceFrames) {
  std::vector<double> refErrors;
  st.refRangeErrors.assign(st.delayRanges.size(), 0.0);
  const int positions = st.walking ? st.warmup + st.frames : 1;
  PropagationSettings refSettings = st.s;
  refSettings.seed = st.s.seed + 1000003;
  for (int f = 0; f < positions; ++f) {
    double e = 0.0;
    std::vector<double> byRange;
    st.refs.push_back(referenceResponse(st.scene, refSettings, st.at(f), referenceFrames, &e, 0,
                                        &st.delayRanges, &byRange));
    refErrors.push_back(e);
    for (size_t r = 0; r < byRange.size(); ++r) st.refRangeErrors[r] += byRange[r] / positions;
    std::fprintf(stderr, "\rreference %d/%d", f + 1, positions);
  }
  st.refError = std::accumulate(refErrors.begin(), refErrors.end(), 0.0) / double(refErrors.size());
}

Json describe(const Study& st, const NoiseMetrics& m) {
  return Json{
      {"error", m.meanError},        {"error_corrected_for_reference", st.corrected(m.meanError)},
      {"flicker", m.meanFlicker},    {"bias", m.bias},
      {"energy_bias", m.energyBias}, {"error_per_frame", m.errorPerFrame}};
}

/// The report's header: settings and the references.
Json header(const CommonOptions& c, const NoiseOptions& o, const Study& st) {
  Json j;
  j["benchmark"] = "noise";
  j["scene"] = c.scene;
  j["rays_per_frame"] = st.s.raysPerFrame;
  j["max_order"] = st.s.maxOrder;
  j["tau_s"] = st.s.cacheTau;
  j["frame_rate"] = st.s.frameRate;
  j["walk_speed_mps"] = o.walkSpeed;
  j["frames_measured"] = c.frames;
  j["warmup_frames"] = st.warmup;
  Json refByRange;
  for (size_t r = 0; r < st.delayRanges.size(); ++r)
    refByRange[rangeName(r)] = st.refRangeErrors[r];
  j["reference"] = {{"frames", o.referenceFrames},
                    {"rays", double(o.referenceFrames) * st.s.raysPerFrame},
                    {"own_relative_error", st.refError},
                    {"own_relative_error_by_order", refByRange}};
  j["metric"] =
      "L2 over 8 bands x 10 ms bins of the energy response, relative to the reference's L2 norm";
  return j;
}

/// What the DPC weightings measured, by name ("dpc_window", "dpc_ema", "dpc_seed").
struct DpcResults {
  std::map<std::string, double> error;                    ///< corrected mean error
  std::map<std::string, std::vector<double>> rangeError;  ///< corrected, per delay range
  std::map<std::string, std::vector<double>> energy;      ///< total energy per frame
};

DpcResults measureDpc(const Study& st, Json& j) {
  DpcResults d;
  for (auto [name, weighting] :
       {std::pair{"dpc_window", DpcWeighting::kWindow}, std::pair{"dpc_ema", DpcWeighting::kEma},
        std::pair{"dpc_seed", DpcWeighting::kSeed}}) {
    PropagationSettings p = st.s;
    p.estimator = Estimator::kDpc;
    p.dpcWeighting = weighting;
    std::fprintf(stderr, "\r%s...            ", name);
    const NoiseMetrics m = st.measure(p, st.warmup, st.frames, st.delayRanges);
    j["estimators"][name] = describe(st, m);
    d.energy[name] = m.energyPerFrame;
    d.error[name] = st.corrected(m.meanError);
    for (size_t r = 0; r < m.errorByRange.size(); ++r)
      d.rangeError[name].push_back(correctedBy(m.errorByRange[r], st.refRangeErrors[r]));
  }
  return d;
}

/// The estimator's own bias, free of Monte Carlo error: path tracing with the same seed traces
/// the same rays in every frame, so the window's total energy at frame f must equal the mean
/// of path tracing's over the frames in its window (all frames so far, at most W), and the
/// EMA's the same exponential average of them, up to float rounding (and the coarse store's
/// rounding when the budget is hit).
Json energyBiasVsSameRays(const Study& st, const DpcResults& d) {
  PropagationSettings p = st.s;
  p.estimator = Estimator::kPathTracing;
  const NoiseMetrics m = st.measure(p, st.warmup, st.frames, {});
  const std::vector<double> window =
      cacheAveraged(m.energyPerFrame, DpcWeighting::kWindow, st.s.cacheTau, st.s.frameRate);
  const std::vector<double> ema =
      cacheAveraged(m.energyPerFrame, DpcWeighting::kEma, st.s.cacheTau, st.s.frameRate);
  double sumWindow = 0.0, sumEma = 0.0, sumPtWindow = 0.0, sumPtEma = 0.0;
  for (size_t f = size_t(st.warmup); f < window.size(); ++f) {
    sumPtWindow += window[f];
    sumPtEma += ema[f];
    sumWindow += d.energy.at("dpc_window")[f];
    sumEma += d.energy.at("dpc_ema")[f];
  }
  return {{"dpc_window", sumWindow / sumPtWindow - 1.0},
          {"dpc_ema", sumEma / sumPtEma - 1.0},
          {"note",
           "total energy over the measured frames against path tracing of the same rays, "
           "averaged as the estimator averages (window: mean of the last W frames; ema: "
           "exponential); free of Monte Carlo error, so it isolates the estimator's own bias"}};
}

/// Plain path tracing at 1x, 2x, 4x ... the rays: error ~ rays^-1/2. Returns the overall
/// curve and appends one curve per delay range to `byRange`.
ErrorCurve measurePathTracing(const Study& st, const std::vector<int>& multipliers,
                              std::vector<ErrorCurve>& byRange, Json& j) {
  ErrorCurve pt;
  byRange.assign(st.delayRanges.size(), {});
  for (int k : multipliers) {
    PropagationSettings p = st.s;
    p.estimator = Estimator::kPathTracing;
    p.raysPerFrame = st.s.raysPerFrame * k;
    std::fprintf(stderr, "\rpath tracing x%d...     ", k);
    const NoiseMetrics m = st.measure(p, 0, std::min(st.frames, 20), st.delayRanges);
    j["path_tracing"][std::to_string(k) + "x"] = describe(st, m);
    pt.push_back({double(k), st.corrected(m.meanError)});
    for (size_t r = 0; r < st.delayRanges.size(); ++r)
      byRange[r].push_back({double(k), correctedBy(m.errorByRange[r], st.refRangeErrors[r])});
  }
  return pt;
}

/// Equal-noise ray ratio: interpolate log(error) against log(rays) between the bracketing
/// path-tracing runs, or extrapolate along the last two with their fitted slope.
double equalNoise(const ErrorCurve& pt, double dpcError, std::string* how) {
  double ratio = NAN;
  if (how) *how = "interpolated";
  for (size_t i = 0; i + 1 < pt.size(); ++i)
    if (pt[i].second >= dpcError && pt[i + 1].second <= dpcError && dpcError > 0.0) {
      const double t =
          std::log(pt[i].second / dpcError) / std::log(pt[i].second / pt[i + 1].second);
      ratio = std::exp(std::log(pt[i].first) + t * std::log(pt[i + 1].first / pt[i].first));
    }
  if (std::isnan(ratio) && pt.size() >= 2 && dpcError > 0.0) {
    const auto& a = pt[pt.size() - 2];
    const auto& b = pt.back();
    const double slope = std::log(b.second / a.second) / std::log(b.first / a.first);
    ratio = b.first * std::pow(dpcError / b.second, 1.0 / slope);
    if (how) *how = "extrapolated with slope " + std::to_string(slope);
  }
  return ratio;
}

/// The rays path tracing needs for the DPC's error, overall and per delay range.
void addEqualNoise(const Study& st, const DpcResults& d, const ErrorCurve& pt,
                   const std::vector<ErrorCurve>& ptRange, Json& j) {
  std::string how;
  const double ratio = equalNoise(pt, d.error.at("dpc_ema"), &how);
  std::string howWindow;
  const double ratioWindow = equalNoise(pt, d.error.at("dpc_window"), &howWindow);
  Json byOrder;
  for (size_t r = 0; r < st.delayRanges.size(); ++r) {
    byOrder[rangeName(r)] = equalNoise(ptRange[r], d.rangeError.at("dpc_window")[r], nullptr);
    j["order_ranges_as_delays_s"][rangeName(r)] = {st.delayRanges[r].first,
                                                   st.delayRanges[r].second};
  }
  j["equal_noise_ray_ratio_by_order"] = byOrder;
  j["equal_noise_ray_ratio_by_order_estimator"] = "dpc_window (the default)";
  j["energy_bias"] = j["estimators"]["dpc_window"]["energy_bias"];
  j["energy_bias_note"] =
      "dpc_window's total energy over the measured frames vs the reference, signed; the "
      "reference's own relative error is reference.own_relative_error";
  j["equal_noise_ray_ratio"] = {
      {"dpc_ema", ratio}, {"how", how}, {"dpc_window", ratioWindow}, {"how_window", howWindow}};
}

/// --warmup, or by default 2 tau (the scene's, or --tau) at the scene's frame rate.
int warmupFrames(const CommonOptions& c, const NoiseOptions& o) {
  if (o.warmup >= 0) return o.warmup;
  const SceneDesc scene = loadScene(c.scene);
  const double tau = c.tau ? *c.tau : scene.propagation.cacheTau;
  return int(std::ceil(2.0 * tau * scene.propagation.frameRate));
}

}  // namespace

int benchNoise(const CommonOptions& c, const NoiseOptions& o) {
  Study st;
  st.warmup = warmupFrames(c, o);
  st.scene = firstSourceOnly(loadScene(c.scene));
  st.s = settingsFor(st.scene, c);
  if (!c.rays) st.s.raysPerFrame = 4096;
  st.at = walker(st.scene, o.walkSpeed, st.s.frameRate);
  st.frames = c.frames;
  st.walking = o.walkSpeed > 0.0;
  st.delayRanges = delayRangesOf(st);
  computeReferences(st, o.referenceFrames);
  Json j = header(c, o, st);
  const DpcResults d = measureDpc(st, j);
  j["energy_bias_vs_same_rays"] = energyBiasVsSameRays(st, d);
  std::vector<ErrorCurve> ptRange;
  const ErrorCurve pt = measurePathTracing(st, o.ptMultipliers, ptRange, j);
  std::fprintf(stderr, "\r                         \r");
  addEqualNoise(st, d, pt, ptRange, j);
  printReport(j);
  return 0;
}

}  // namespace dpc::bench
