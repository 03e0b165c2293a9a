// `dpc-bench dynamic`: door step response, moving objects against baked geometry, and a
// walking source against a static one.
#include "bench/dynamic_bench.h"

#include <cmath>
#include <cstdio>
#include <ctime>
#include <numeric>
#include <utility>
#include <vector>

#include "bench/bench_util.h"
#include "bench/noise_study.h"
#include "engine/simulation.h"
#include "testing/test_scenes.h"

namespace dpc::bench {
namespace {

/// One step-response case: the weighting (named as reported) and its time constant.
struct StepCase {
  const char* name;
  DpcWeighting weighting;
  double tau, timeConstant;
};

/// The late energy (band 3) of each of `frames` frames.
std::vector<double> lateEnergy(Simulation& sim, const glm::vec3& listener, const Pose& door,
                               int frames) {
  FrameInputs in = sim.inputsAt(listener);
  in.objectPoses = {door};
  std::vector<double> v;
  for (int f = 0; f < frames; ++f)
    sim.runFrame(in), v.push_back(double(sim.result(0).energy.total()[3]));
  return v;
}

/// Time of the frame after the change (0 = the first frame with the new pose) from which the
/// readout has completed 90 % of the step from `from` to `to`; frame k is at k T after the
/// change. NaN if it never does.
double t90(const std::vector<double>& v, double from, double to, double T) {
  for (size_t k = 0; k < v.size(); ++k)
    if ((v[k] - from) / (to - from) >= 0.9) return double(k) * T;
  return std::nan("");
}

/// The door shut and opened again after the cache settled with it open.
Json stepCase(const StepCase& c, int rays) {
  SceneDesc sc = test::twoRooms(c.weighting, float(c.timeConstant));
  sc.propagation.raysPerFrame = rays;
  Simulation sim(sc);
  const glm::vec3 L = sc.listeners[0].position;
  const double T = 1.0 / sc.propagation.frameRate;
  const int settle = int(std::ceil(std::max(3.0 * c.tau, 1.5) / T));
  const int span = int(std::ceil(3.0 * c.tau / T));
  lateEnergy(sim, L, test::kDoorOpen, settle);
  const std::vector<double> open = lateEnergy(sim, L, test::kDoorOpen, span);
  const double openMean = std::accumulate(open.begin(), open.end(), 0.0) / double(span);
  double var = 0.0;
  for (double x : open) var += (x - openMean) * (x - openMean);
  const double openSd = std::sqrt(var / double(span - 1));
  const std::vector<double> shut = lateEnergy(sim, L, test::kDoorShut, span);
  const std::vector<double> reopen = lateEnergy(sim, L, test::kDoorOpen, span);
  const double shutLevel = shut.back();
  Json e;
  e["weighting"] = c.name;
  e["tau"] = c.tau;
  e["time_constant"] = c.timeConstant;
  e["open_level"] = openMean;
  e["open_relative_sd"] = openSd / openMean;
  e["t90_shut"] = t90(shut, openMean, shutLevel, T);
  e["t90_open"] = t90(reopen, shutLevel, openMean, T);
  e["frame_period"] = T;
  e["shut"] = shut;
  e["reopen"] = reopen;
  std::fprintf(stderr, "%s tau %.2f: t90 shut %.2f open %.2f, sd %.3f\n", c.name, c.tau,
               double(e["t90_shut"]), double(e["t90_open"]), openSd / openMean);
  return e;
}

/// Door step response per weighting and tau. "ema_matched": the EMA with the time constant
/// that completes 90 % of a step at tau (1 - exp(-tau / tau_e) = 0.9, tau_e = tau / ln 10),
/// for the noise comparison.
Json stepResponses(int rays) {
  Json steps = Json::array();
  const std::pair<const char*, DpcWeighting> weightings[] = {{"ema", DpcWeighting::kEma},
                                                             {"seed", DpcWeighting::kSeed},
                                                             {"window", DpcWeighting::kWindow}};
  for (const auto& [name, w] : weightings)
    for (double tau : {0.25, 0.5, 1.0, 2.0}) {
      steps.push_back(stepCase({name, w, tau, tau}, rays));
      if (w == DpcWeighting::kEma)
        steps.push_back(stepCase({"ema_matched", w, tau, tau / std::log(10.0)}, rays));
    }
  return steps;
}

/// A 20 x 5 x 20 m room with n panels as moving objects (first) and the same panels baked
/// into the static mesh (second).
std::pair<SceneDesc, SceneDesc> panelScenes(int n, int rays) {
  SceneDesc moving = test::makeShoebox({20, 5, 20}, Bands(0.2f), 0.5f, {3, 2, 3}, {15, 2, 15});
  moving.propagation.estimator = Estimator::kPathTracing;
  moving.propagation.raysPerFrame = rays;
  moving.propagation.maxOrder = 30;
  SceneDesc baked = moving;
  for (int k = 0; k < n; ++k) {
    ObjectDesc o;
    o.name = "panel" + std::to_string(k);
    test::addPanel(o.mesh, {0, 0, 0}, {0.5f, 0, 0}, {0, 1, 0}, 0);
    ObjectKeyframe key;
    key.position = {1.f + float(k % 10) * 1.8f, 0.5f + float(k / 50),
                    1.f + float(k / 10 % 5) * 3.6f};
    o.trajectory = {key};
    for (glm::vec3 v : o.mesh.vertices) baked.mesh.vertices.push_back(v + key.position);
    const auto base = uint32_t(baked.mesh.vertices.size() - 4);
    for (const auto& t : o.mesh.triangles) {
      baked.mesh.triangles.push_back({base + t[0] - 0, base + t[1], base + t[2]});
      baked.mesh.materialIndex.push_back(0);
    }
    moving.objects.push_back(o);
  }
  return {moving, baked};
}

/// CPU time of `frames` frames with n moving objects against the same triangles baked.
Json movingObjectsCase(int n, int rays, int frames) {
  const auto [moving, baked] = panelScenes(n, rays);
  Simulation sm(moving), sb(baked);
  std::vector<Pose> poses(static_cast<size_t>(n));
  auto cpu = [] { return double(std::clock()) / CLOCKS_PER_SEC; };
  double movingCpu = 0.0, staticCpu = 0.0;
  for (int f = 0; f < frames; ++f) {
    for (int k = 0; k < n; ++k) {
      const ObjectKeyframe& key = moving.objects[size_t(k)].trajectory[0];
      poses[size_t(k)] = Pose{key.position + glm::vec3(0.f, 0.f, 0.01f * float(f % 7)),
                              glm::angleAxis(0.05f * float(f), glm::vec3(0, 1, 0))};
    }
    double t0 = cpu();
    FrameInputs in = sm.inputsAt(moving.listeners[0].position);
    in.objectPoses = poses;
    sm.runFrame(in);
    movingCpu += cpu() - t0;
    t0 = cpu();
    sb.runFrame(baked.listeners[0].position);
    staticCpu += cpu() - t0;
  }
  Json e;
  e["objects"] = n;
  e["triangles"] = sb.geometry().triangleCount();
  e["moving_cpu_ms_per_frame"] = 1e3 * movingCpu / frames;
  e["static_cpu_ms_per_frame"] = 1e3 * staticCpu / frames;
  e["ratio"] = movingCpu / staticCpu;
  std::fprintf(stderr, "%d objects: moving/static cpu %.3f\n", n, movingCpu / staticCpu);
  return e;
}

/// The walking-source study's room, settings and reference responses.
struct WalkingSource {
  SceneDesc room;
  double T = 0.0, speed = 1.5;
  int warm = 0, measured = 25;
  std::vector<EnergyResponse> refs;  ///< per frame, at the walking source's position
  double refError = 0.0;             ///< the references' largest own relative error

  glm::vec3 sourceAt(int f) const {
    return room.sources[0].position + glm::vec3(float(speed * T * f), 0.f, 0.f);
  }
};

WalkingSource walkingSource(int rays) {
  WalkingSource w;
  w.room = test::makeShoebox({10, 3, 7}, Bands(0.15f), 0.5f, {2, 1.6f, 2}, {8, 1.6f, 5});
  w.room.propagation.raysPerFrame = rays;
  w.room.propagation.frameRate = 10.f;
  w.room.propagation.cacheTau = 0.5f;
  w.T = 1.0 / w.room.propagation.frameRate;
  w.warm = int(std::lround(w.room.propagation.cacheTau / w.T));
  const int total = w.warm + w.measured;
  PropagationSettings refSettings = w.room.propagation;
  refSettings.raysPerFrame = 4 * rays;
  refSettings.seed += 1000003;
  for (int f = 0; f < total; ++f) {
    SceneDesc at = w.room;
    at.sources[0].position = w.sourceAt(f);
    double e = 0.0;
    w.refs.push_back(referenceResponse(at, refSettings, w.room.listeners[0].position, 16, &e));
    w.refError = std::max(w.refError, e);
    std::fprintf(stderr, "\rmoving-source references %d/%d", f + 1, total);
  }
  std::fprintf(stderr, "\n");
  return w;
}

/// One estimator with the source walking or static, against the matching references.
Json walkingSourceCase(const WalkingSource& w, bool moving, Estimator est) {
  const EnergyResponse& staticRef = w.refs.front();
  PropagationSettings ps = w.room.propagation;
  ps.estimator = est;
  const NoiseMetrics m = measureNoise(
      w.room, ps, w.warm, w.measured, [&](int) { return w.room.listeners[0].position; },
      [&](int f) -> const EnergyResponse& { return moving ? w.refs[size_t(f)] : staticRef; }, 0,
      moving ? std::function<glm::vec3(int)>([&](int f) { return w.sourceAt(f); }) : nullptr);
  Json e;
  e["estimator"] = est == Estimator::kDpc ? "dpc_window" : "path_tracing";
  e["source"] = moving ? "walking" : "static";
  e["mean_error"] = m.meanError;
  e["mean_flicker"] = m.meanFlicker;
  e["error_per_frame"] = m.errorPerFrame;
  std::fprintf(stderr, "%s %s: error %.3f flicker %.3f\n", moving ? "walking" : "static",
               est == Estimator::kDpc ? "window" : "path tracing", m.meanError, m.meanFlicker);
  return e;
}

/// Noise while a source walks at 1.5 m/s vs standing still: relative RMS error of each frame's
/// energy response (10 ms bins, all bands; bench/noise_study.h) against converged path
/// tracing at that frame's source position; path tracing and the DPC window (tau 0.5 s) with
/// the same seed, i.e. the same rays.
Json movingSource(int rays) {
  const WalkingSource w = walkingSource(rays);
  Json cases = Json::array();
  for (bool moving : {true, false})
    for (Estimator est : {Estimator::kPathTracing, Estimator::kDpc})
      cases.push_back(walkingSourceCase(w, moving, est));
  Json ms;
  ms["scene"] = "shoebox 10 x 3 x 7 m, absorption 0.15, scattering 0.5";
  ms["speed_m_per_s"] = w.speed;
  ms["tau"] = w.room.propagation.cacheTau;
  ms["frame_period"] = w.T;
  ms["warmup_frames"] = w.warm;
  ms["reference_relative_error"] = w.refError;
  ms["cases"] = cases;
  return ms;
}

}  // namespace

int benchDynamic(const DynamicOptions& o) {
  auto want = [&](const char* part) { return o.parts.find(part) != std::string::npos; };
  Json j;
  j["machine"] = "shared 2-core machine under load from other builds: ratios within one run";
  j["scene"] = "two rooms 10 x 3 x 4 m, 1 x 2 m doorway, door shut/open by pose jumps";
  j["rays_per_frame"] = o.rays;
  j["step_response"] = want("step") ? stepResponses(o.rays) : Json::array();
  // Frame time with N moving objects vs the same triangles baked into the static mesh.
  Json objs = Json::array();
  if (want("objects"))
    for (int n : {1, 10, 100}) objs.push_back(movingObjectsCase(n, o.rays, o.frames));
  j["moving_objects"] = objs;
  if (want("moving_source")) j["moving_source"] = movingSource(o.rays);
  printReport(j);
  return 0;
}

}  // namespace dpc::bench
