#include "bench/bake_interp_bench.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>

#include "analysis/room_parameters.h"
#include "bench/bench_util.h"
#include "common/random.h"
#include "engine/baked_field.h"
#include "engine/simulation.h"
#include "synthesis/spatial_synthesizer.h"
#include "testing/test_scenes.h"

namespace dpc::bench {
namespace {

/// The diffuse box: 16 x 4 x 12 m, absorption 0.2, scattering 0.8 (every spacing up to 4 m
/// leaves a grid of at least 3 x 3 probes). Probes and points at the source's height.
constexpr glm::vec3 kRoom{16.f, 4.f, 12.f};
constexpr float kHeight = 1.6f;
constexpr double kIrLength = 1.0;

SceneDesc diffuseRoom(const BakeInterpOptions& o) {
  SceneDesc s = test::makeShoebox(kRoom, Bands(0.2f), 0.8f, {3.1f, kHeight, 2.7f},
                                  {8.f, kHeight, 6.f}, 0.5f);
  s.propagation.estimator = Estimator::kPathTracing;
  s.propagation.raysPerFrame = o.rays;
  s.propagation.threads = o.threads;
  s.propagation.irLength = float(kIrLength);
  return s;
}

/// One simulated response: late energy [bin][band] (the mean of the frames), its first-order
/// SH energy summed over the bins [channel][band] (engine/sh_energy_response.h), and the
/// direct sound.
struct Response {
  std::vector<float> late;
  std::vector<double> sh = std::vector<double>(4 * kNumBands, 0.0);
  DirectSound direct;
};

Response simulate(Simulation& sim, const glm::vec3& p, uint64_t seed, int frames) {
  sim.restart(seed);
  Response r;
  for (int f = 0; f < frames; ++f) {
    sim.runFrame(p);
    const auto& bins = sim.result(0).energy.bins();
    r.late.resize(bins.size() * kNumBands, 0.f);
    for (size_t k = 0; k < bins.size(); ++k)
      for (int b = 0; b < kNumBands; ++b)
        r.late[k * kNumBands + size_t(b)] += bins[k][b] / float(frames);
    const std::span<const float> sh = sim.shEnergy(0).data();
    for (size_t i = 0; i < sh.size(); ++i) r.sh[i % r.sh.size()] += sh[i] / frames;
  }
  r.direct = sim.result(0).direct;
  return r;
}

/// Per band, |r_test - r_ref| of the late response's energy vectors r = (X, Y, Z) / W (the
/// first-order SH energy over its energy: 0 for an isotropic field, 1 for one plane wave).
void compareDirection(const std::vector<double>& test, const std::vector<double>& ref,
                      std::vector<double>& dr) {
  for (size_t b = 0; b < size_t(kNumBands); ++b) {
    double d2 = 0.0;
    for (size_t c = 1; c < 4; ++c) {
      const double e = test[c * kNumBands + b] / test[b] - ref[c * kNumBands + b] / ref[b];
      d2 += e * e;
    }
    dr.push_back(std::sqrt(d2));
  }
}

/// Band b of a response with its direct sound, as a decay (doubles) for the room parameters.
std::vector<double> bandSeries(const std::vector<float>& late, const DirectSound& d, int b) {
  std::vector<double> e(late.size() / kNumBands);
  for (size_t k = 0; k < e.size(); ++k) e[k] = late[k * kNumBands + size_t(b)];
  const size_t k = size_t(d.delaySeconds / Simulation::kEnergyBinSeconds);
  if (d.visible && k < e.size()) e[k] += d.intensity[b];
  return e;
}

/// Per band: energy error (dB) and C80 error (dB) of `test` against `ref`, both with ref's
/// direct sound (the live direct sound of playback).
void compare(const std::vector<float>& test, const Response& ref, std::vector<double>& dE,
             std::vector<double>& dC80) {
  for (int b = 0; b < kNumBands; ++b) {
    const auto t = bandSeries(test, ref.direct, b), r = bandSeries(ref.late, ref.direct, b);
    const auto pt = audio::analyzeEnergyDecay(t.data(), t.size(), Simulation::kEnergyBinSeconds);
    const auto pr = audio::analyzeEnergyDecay(r.data(), r.size(), Simulation::kEnergyBinSeconds);
    dE.push_back(10.0 * std::log10(pt.energy / pr.energy));
    dC80.push_back(pt.c80 - pr.c80);
  }
}

/// The test points: uniform in the hull of the coarsest grid, fixed seed.
std::vector<glm::vec3> testPoints(const BakeInterpOptions& o, double coarsest) {
  Rng rng(0x6a09e667ULL, 7);
  std::vector<glm::vec3> pts;
  const float lo = float(coarsest / 2);
  for (int i = 0; i < o.points; ++i) {
    const float x = lo + rng.uniform() * (kRoom.x - 2 * lo);
    const float z = lo + rng.uniform() * (kRoom.z - 2 * lo);
    pts.push_back({x, kHeight, z});
  }
  return pts;
}

/// The probe grid of spacing h around a point (the 2 x 2 cell corners, cell centres of the
/// dpc-bake grid), simulated once per grid node (cache) and interpolated at the point.
class GridProbes {
 public:
  GridProbes(Simulation& sim, glm::vec3 source, double h, int frames)
      : sim_(sim), source_(source), h_(h), frames_(frames) {}
  /// The interpolated late response at p, and in `sh` its SH energy: the probes' blended with
  /// the same weights, as the player blends them.
  std::vector<float> interpolate(const glm::vec3& p, std::vector<double>& sh) {
    auto field = std::make_shared<BakedField>();
    std::vector<const Response*> used;
    const int i0 = int(std::floor(p.x / h_ - 0.5)), j0 = int(std::floor(p.z / h_ - 0.5));
    for (int i = i0; i <= i0 + 1; ++i)
      for (int j = j0; j <= j0 + 1; ++j) {
        field->probes.push_back(node(i, j));
        const Response& r = probe(i, j);
        used.push_back(&r);
        field->late.insert(field->late.end(), r.late.begin(), r.late.end());
      }
    field->sources = {source_};
    field->bins = field->late.size() / (field->probes.size() * kNumBands);
    BakeInterpolator interp(field, sim_.tracer());
    EnergyResponse out(kIrLength, Simulation::kEnergyBinSeconds);
    if (!interp.locate(p)) return {};
    interp.response(0, out);
    sh.assign(4 * kNumBands, 0.0);
    for (const ProbeWeight& w : interp.weights())
      for (size_t i = 0; i < sh.size(); ++i) sh[i] += w.weight * used[w.probe]->sh[i];
    std::vector<float> late(field->bins * kNumBands);
    for (size_t k = 0; k < field->bins; ++k)
      for (int b = 0; b < kNumBands; ++b) late[k * kNumBands + size_t(b)] = out.bins()[k][b];
    return late;
  }
  size_t simulated() const { return cache_.size(); }

 private:
  glm::vec3 node(int i, int j) const {
    return {float((i + 0.5) * h_), kHeight, float((j + 0.5) * h_)};
  }
  const Response& probe(int i, int j) {
    auto it = cache_.find({i, j});
    if (it == cache_.end()) {
      const uint64_t seed = hashCombine(hashCombine(uint64_t(h_ * 1000), uint64_t(i)), j);
      it = cache_.emplace(std::make_pair(i, j), simulate(sim_, node(i, j), seed, frames_)).first;
    }
    return it->second;
  }
  Simulation& sim_;
  glm::vec3 source_;
  double h_;
  int frames_;
  std::map<std::pair<int, int>, Response> cache_;
};

double meanAbs(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += std::abs(x);
  return v.empty() ? NAN : s / double(v.size());
}

/// Per band mean |error| over the points (v holds point-major, 8 bands each).
Json perBand(const std::vector<double>& v) {
  Json j = Json::array();
  for (int b = 0; b < kNumBands; ++b) {
    std::vector<double> band;
    for (size_t i = size_t(b); i < v.size(); i += kNumBands) band.push_back(v[i]);
    j.push_back(meanAbs(band));
  }
  return j;
}

Json errorReport(const std::vector<double>& dE, const std::vector<double>& dC80,
                 const std::vector<double>& dR) {
  std::vector<double> aE, aC;
  for (double x : dE) aE.push_back(std::abs(x));
  for (double x : dC80) aC.push_back(std::abs(x));
  return {{"energy_vector_mean_abs", meanAbs(dR)},
          {"energy_vector_p95_abs", percentile(dR, 0.95)},
          {"energy_vector_max_abs", percentile(dR, 1.0)},
          {"energy_db_mean_abs", meanAbs(dE)},
          {"energy_db_p95_abs", percentile(aE, 0.95)},
          {"energy_db_max_abs", percentile(aE, 1.0)},
          {"energy_db_mean_abs_per_band", perBand(dE)},
          {"c80_db_mean_abs", meanAbs(dC80)},
          {"c80_db_p95_abs", percentile(aC, 0.95)},
          {"c80_db_max_abs", percentile(aC, 1.0)},
          {"c80_db_mean_abs_per_band", perBand(dC80)}};
}

/// Seconds per locate (nearest probes and their visibility, no response) against the probe
/// count, probes scattered uniformly over the room's floor plan at the listener height (a
/// level-sized bake's search; one bin per response to keep the memory small).
Json locateCost(Simulation& sim, glm::vec3 source) {
  Json rows = Json::array();
  for (const size_t probes : {size_t(1000), size_t(10000), size_t(100000)}) {
    auto field = std::make_shared<BakedField>();
    Rng rng(11, probes);
    for (size_t p = 0; p < probes; ++p)
      field->probes.push_back({rng.uniform() * kRoom.x, kHeight, rng.uniform() * kRoom.z});
    field->sources = {source};
    field->bins = 1;
    field->late.assign(probes * kNumBands, 0.f);
    BakeInterpolator interp(field, sim.tracer());
    const int n = 200;
    const auto t0 = std::chrono::steady_clock::now();
    for (int i = 0; i < n; ++i)
      interp.locate({0.5f + rng.uniform() * (kRoom.x - 1), kHeight,
                     0.5f + rng.uniform() * (kRoom.z - 1)});
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    rows.push_back({{"probes", probes}, {"seconds_per_locate", s / n}});
  }
  return rows;
}

/// Seconds per locate + `read` (one source's response) at n random points of the room.
template <typename Read>
double secondsPerFrame(BakeInterpolator& interp, int n, Read read) {
  Rng rng(3, 5);
  const auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < n; ++i) {
    const glm::vec3 p{0.5f + rng.uniform() * (kRoom.x - 1), kHeight,
                      0.5f + rng.uniform() * (kRoom.z - 1)};
    if (interp.locate(p)) read();
  }
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / n;
}

/// Seconds per locate + response of one source over a full 1 m grid of the room (P probes):
/// mono (the energy response) and spatial (shared among the 8 default directions by the SH
/// energy of an isotropic field).
Json interpolationCost(Simulation& sim, glm::vec3 source) {
  auto field = std::make_shared<BakedField>();
  for (float x = 0.5f; x < kRoom.x; x += 1.f)
    for (float z = 0.5f; z < kRoom.z; z += 1.f) field->probes.push_back({x, kHeight, z});
  field->sources = {source};
  field->bins = EnergyResponse(kIrLength, Simulation::kEnergyBinSeconds).binCount();
  field->late.assign(field->probes.size() * field->bins * kNumBands, 1e-6f);
  fillUniformDirections(*field);
  BakeInterpolator interp(field, sim.tracer());
  EnergyResponse out(kIrLength, Simulation::kEnergyBinSeconds);
  DirectionalEnergyResponse spatial(kIrLength, Simulation::kEnergyBinSeconds,
                                    defaultSpatialDirections());
  const int n = 2000;
  const double mono = secondsPerFrame(interp, n, [&] { interp.response(0, out); });
  const double rays = double(interp.visibilityRays()) / n;
  const double dirs = secondsPerFrame(interp, n / 4, [&] { interp.directional(0, spatial); });
  const size_t directional = field->directionalBins() * field->shChannels() * kNumBands;
  return {{"probes", field->probes.size()},
          {"seconds_per_listener_frame_one_source", mono},
          {"seconds_per_listener_frame_one_source_8_directions", dirs},
          {"visibility_rays_per_frame", rays},
          {"bytes_per_probe_and_source_in_memory",
           (field->bins * kNumBands + directional) * sizeof(float)},
          {"response_bins", field->bins},
          {"locate_seconds_vs_probes", locateCost(sim, source)}};
}

/// One spacing's errors at the points against their references (a row of the report).
Json spacingRow(Simulation& sim, glm::vec3 source, double h, const BakeInterpOptions& o,
                const std::vector<glm::vec3>& points, const std::vector<Response>& refs) {
  GridProbes grid(sim, source, h, o.frames);
  std::vector<double> dE, dC, dR, sh;
  for (size_t i = 0; i < points.size(); ++i) {
    compare(grid.interpolate(points[i], sh), refs[i], dE, dC);
    compareDirection(sh, refs[i].sh, dR);
  }
  Json row = errorReport(dE, dC, dR);
  row["spacing_m"] = h;
  row["probes_simulated"] = grid.simulated();
  std::fprintf(stderr,
               "spacing %.2f m: energy error %.2f dB mean, %.2f dB max; C80 %.2f dB; energy "
               "vector %.3f\n",
               h, meanAbs(dE), double(row["energy_db_max_abs"]), meanAbs(dC), meanAbs(dR));
  return row;
}

}  // namespace

int benchBakeInterp(const BakeInterpOptions& o) {
  const SceneDesc scene = diffuseRoom(o);
  Simulation sim(scene);
  sim.enableShEnergy(1, 0.01);
  double coarsest = 0.0;
  for (double h : o.spacings) coarsest = std::max(coarsest, h);
  const std::vector<glm::vec3> points = testPoints(o, coarsest);
  std::vector<Response> refs;
  std::vector<double> noiseE, noiseC, noiseR;
  const auto t0 = std::chrono::steady_clock::now();
  for (size_t i = 0; i < points.size(); ++i) {
    refs.push_back(simulate(sim, points[i], hashCombine(0xabcULL, i), o.frames));
    const Response again = simulate(sim, points[i], hashCombine(0xdefULL, i), o.frames);
    compare(again.late, refs.back(), noiseE, noiseC);
    compareDirection(again.sh, refs.back().sh, noiseR);
  }
  const double liveFrame = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0)
                               .count() / double(2 * points.size() * size_t(o.frames));
  Json spacings = Json::array();
  for (double h : o.spacings)
    spacings.push_back(spacingRow(sim, scene.sources[0].position, h, o, points, refs));
  Json report = {{"benchmark", "bake-interp"},
                 {"room_m", {kRoom.x, kRoom.y, kRoom.z}},
                 {"absorption", 0.2},
                 {"scattering", 0.8},
                 {"rays_per_frame", o.rays},
                 {"frames_per_response", o.frames},
                 {"points", o.points},
                 {"interpolation", "inverse distance squared, 4 nearest visible probes"},
                 {"monte_carlo_floor", errorReport(noiseE, noiseC, noiseR)},
                 {"spacings", spacings},
                 {"cost", interpolationCost(sim, scene.sources[0].position)}};
  report["cost"]["live_frame_seconds_same_rays"] = liveFrame;
  printReport(report);
  return 0;
}

}  // namespace dpc::bench
