// Baked playback and the exact early paths: what a pair played from a bake hears (the loaded
// late response, the live direct sound, the live exact paths) must add up to the whole
// response the bake traced and stored in `energy`, each exact path once, whatever the number
// of paths the probe found (docs/bake-format.md: `early/`).
#include <hdf5.h>

#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>

#include "bake/bake_file.h"
#include "bake/bake_loader.h"
#include "runtime/offline_renderer.h"
#include "runtime/propagation_stage.h"
#include "runtime/response_snapshot.h"
#include "scene/trajectory.h"
#include "testing/temp_dir.h"
#include "tests/bake/bake_fixtures.h"

using namespace dpc;
using namespace dpc::bake;

namespace {

constexpr int kRays = 16000;

/// The fixture's shoebox (10 x 3 x 7 m, source at 2, 1.6, 3.5 m, listener at 8, 1.6, 3.5 m)
/// with exact paths up to `exactOrder` and 16000 rays: at the listener the bake and live
/// playback then find the same exact paths, 20 up to order 2 and 50 up to order 3 (more than
/// the 32 early/paths keeps).
SceneDesc scene(int exactOrder) {
  SceneDesc s = test_fixtures::shoebox();
  s.propagation.exactOrder = exactOrder;
  s.propagation.raysPerFrame = kRays;
  return s;
}

/// A complete bake of `scene` at the probes `probes` (a probe list) into `path`.
BakeHeader writeBake(const SceneDesc& scene, const std::vector<glm::vec3>& probes,
                     const std::string& path) {
  BakeSettings settings = test_fixtures::quickSettings();
  settings.rays = kRays;
  BakeHeader h = test_fixtures::headerFor(scene, settings, 2.5);
  h.grid.spacingM = 0.0;
  h.grid.heightM = 0.0;
  h.probes.positions = probes;
  h.hashes = settingsHash(scene, settings, probes);
  BakeFile f = BakeFile::create(path, path, h);
  ProbeBaker baker(scene, settings);
  for (size_t p = 0; p < probes.size(); ++p) f.commit(p, baker.bake(p, probes[p]));
  f.markComplete();
  return h;
}

/// A whole float dataset of the file, read with the HDF5 library alone (not dpc's reader).
std::vector<float> readDataset(const std::string& path, const char* name) {
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  REQUIRE(file >= 0);
  const hid_t set = H5Dopen2(file, name, H5P_DEFAULT);
  REQUIRE(set >= 0);
  const hid_t space = H5Dget_space(set);
  std::vector<float> all(size_t(H5Sget_simple_extent_npoints(space)));
  REQUIRE(H5Dread(set, H5T_NATIVE_FLOAT, H5S_ALL, H5S_ALL, H5P_DEFAULT, all.data()) >= 0);
  H5Sclose(space);
  H5Dclose(set);
  H5Fclose(file);
  return all;
}

/// What a pair played from the bake hears at the listener: the snapshot's energy (the loaded
/// late response interpolated at the listener, plus the live direct sound and the live exact
/// paths in the bins of their delays), per band summed over [0, seconds); and the number of
/// live paths.
struct Played {
  Bands early{0.f};
  Bands exact{0.f};   ///< the live exact paths alone, in the window
  Bands beyond{0.f};  ///< the live paths beyond the kEarlyPaths shortest, in the window
  Bands direct{0.f};  ///< the live direct sound, when in the window
  size_t paths = 0;
};

Played playAt(const SceneDesc& scene, const std::string& bake, glm::vec3 listener,
              double seconds) {
  auto shared = std::make_shared<SceneDesc>(scene);
  PropagationStage stage(shared, shared->propagation);
  stage.attachBake(loadBakedField(bake, scene));
  WorldState world;
  evaluateWorld(*shared, 0.0, world);
  world.listenerPositions[0] = listener;
  for (int f = 0; f < 4; ++f) stage.traceWorld(world);
  stage.synthesizeIrs(0);
  ResponseSnapshot snapshot;
  REQUIRE(snapshot.tryStore(stage, world, 0, 1));
  Played out;
  REQUIRE(snapshot.read(0, [&](const ResponseSnapshot::Responses& r) {
    REQUIRE(r.fromBake);
    for (size_t k = 0; k < r.energy->size() && double(k) * 1e-3 < seconds; ++k)
      out.early += (*r.energy)[k];
    for (size_t i = 0; i < r.paths->size(); ++i) {
      const SpecularPath& p = (*r.paths)[i];
      if (double(size_t(p.delaySeconds / 1e-3)) * 1e-3 >= seconds) continue;
      out.exact += p.intensity;
      if (i >= kEarlyPaths) out.beyond += p.intensity;
    }
    if (r.direct->visible && double(size_t(r.direct->delaySeconds / 1e-3)) * 1e-3 < seconds)
      out.direct = r.direct->intensity;
    out.paths = r.paths->size();
  }));
  return out;
}

/// Per band, the sum of a stored [B][8] row over the bins of [0, seconds).
Bands sumBins(const std::vector<float>& row, double seconds) {
  Bands s(0.f);
  for (size_t k = 0; k * 8 < row.size() && double(k) * 1e-3 < seconds; ++k)
    for (int b = 0; b < kNumBands; ++b) s[b] += row[k * 8 + size_t(b)];
  return s;
}

/// Probe p's late response as the bake format defines it (docs/bake-format.md), from the file:
/// `energy` less `early/energy` bin by bin, less the direct sound (`direct/`) in the bin of its
/// delay, each clamped at 0, summed per band over [0, seconds). One source.
Bands lateFromFile(const std::string& path, size_t p, size_t bins, double seconds) {
  const std::vector<float> energy = readDataset(path, "energy");
  const std::vector<float> exact = readDataset(path, "early/energy");
  const std::vector<float> delay = readDataset(path, "direct/delay_s");
  const std::vector<float> direct = readDataset(path, "direct/energy");
  std::vector<float> row(bins * kNumBands);
  for (size_t i = 0; i < row.size(); ++i)
    row[i] = std::max(0.f, energy[p * row.size() + i] - exact[p * row.size() + i]);
  const size_t kd = size_t(double(delay[p]) / 1e-3);
  for (int b = 0; kd < bins && b < kNumBands; ++b)
    row[kd * kNumBands + size_t(b)] =
        std::max(0.f, row[kd * kNumBands + size_t(b)] - direct[p * kNumBands + size_t(b)]);
  return sumBins(row, seconds);
}

}  // namespace

// Oracle: the bake's `energy` at the probe, the response it traced there (estimator, direct
// sound and every exact path of each frame, averaged over the frames), read from the file with
// the HDF5 library. Played at the probe, the late response the loader left plus the live
// direct sound and exact paths must give it back. Both sides hold the same deterministic
// direct sound and exact paths (the live count is checked against the bake's early/found)
// and the same stored estimator bins, so they differ by the float32 rounding of sums of a few
// hundred terms: 1e-4 relative. A path counted twice adds its intensity: with the 32 of
// early/paths taken out and all 50 added live, the 18 beyond add 2.4e-4 of 0.037 in 0..80 ms
// (0.65 %, +0.028 dB); a path dropped takes its intensity away.
TEST_CASE(
    "Baked playback at a probe: late response + live direct sound + live exact paths = "
    "the bake's whole response, with more exact paths than early/paths stores",
    "[bake][playback][heavy]") {
  for (const int order : {2, 3}) {
    test::TempDir dir("bake_early");
    const SceneDesc s = scene(order);
    const glm::vec3 probe = s.listeners[0].position;
    const std::string path = (dir.path() / "b.h5").string();
    const BakeHeader h = writeBake(s, {probe}, path);
    // One probe, one source: `energy` is [1][1][B][8].
    const std::vector<float> stored = readDataset(path, "energy");
    REQUIRE(stored.size() == h.shape.bins * kNumBands);
    const size_t found = size_t(readDataset(path, "early/found")[0]);
    CHECK((order == 2 ? found <= kEarlyPaths : found > kEarlyPaths));
    for (const double seconds : {0.05, 0.08, 0.5}) {
      const Played played = playAt(s, path, probe, seconds);
      const Bands whole = sumBins(stored, seconds);
      CAPTURE(order, seconds, found);
      REQUIRE(played.paths == found);
      const Bands exactStored = sumBins(readDataset(path, "early/energy"), seconds);
      for (int b = 0; b < kNumBands; ++b) {
        // On failure: the excess, and the live paths beyond the 32 shortest it would equal.
        CAPTURE(b, played.early[b] - whole[b], played.beyond[b]);
        CHECK(played.early[b] == Approx(whole[b]).epsilon(1e-4));
        // The bake's exact-path part holds every path the probe found: the live ones here.
        CHECK(exactStored[b] == Approx(played.exact[b]).epsilon(1e-4));
      }
    }
  }
}

// Between probes. Oracle: the file read with the HDF5 library and the bake format's
// definition of the late response (lateFromFile), blended with the weights of two probes
// 1 m either side of the listener (inverse-distance squared: 1/2 each), plus the live direct
// sound and the live exact paths at the listener. So what the listener hears holds no exact
// path of either probe (each probe's every path is out of its late response, not only the
// 32 of early/paths) and each of its own once. Float32 rounding: 1e-4 relative.
TEST_CASE("Baked playback between probes: the blended late responses hold no exact path, the "
          "listener's own are added once",
          "[bake][playback]") {
  test::TempDir dir("bake_early");
  const SceneDesc s = scene(3);
  const glm::vec3 listener = s.listeners[0].position;
  const glm::vec3 dx(1.f, 0.f, 0.f);
  const std::string path = (dir.path() / "b.h5").string();
  const BakeHeader h = writeBake(s, {listener - dx, listener + dx}, path);
  const std::vector<float> found = readDataset(path, "early/found");
  CHECK(std::max(found[0], found[1]) > float(kEarlyPaths));
  for (const double seconds : {0.05, 0.08, 0.5}) {
    const Played played = playAt(s, path, listener, seconds);
    const Bands late = 0.5f * (lateFromFile(path, 0, h.shape.bins, seconds) +
                               lateFromFile(path, 1, h.shape.bins, seconds));
    CAPTURE(seconds, played.paths);
    CHECK(played.paths > kEarlyPaths);
    for (int b = 0; b < kNumBands; ++b)
      CHECK(played.early[b] ==
            Approx(late[b] + played.direct[b] + played.exact[b]).epsilon(1e-4));
  }
}

// The offline render's last energy response (dpc-demo --er-out) of a pair played from a bake.
// Oracle: the bake's `energy` read with the HDF5 library, as in the first case (the render's
// response plus its direct sound gives it back at the probe, float32 rounding: 1e-4). A
// render that kept the untraced pair's empty live response would give the direct sound and
// the exact paths alone (a third of the 0..80 ms energy here).
TEST_CASE("Baked playback: the offline render's energy response of a baked pair is the bake's",
          "[bake][playback]") {
  test::TempDir dir("bake_early");
  SceneDesc s = scene(3);
  s.audio.blockSize = 512;
  const std::string path = (dir.path() / "b.h5").string();
  writeBake(s, {s.listeners[0].position}, path);
  const std::vector<float> stored = readDataset(path, "energy");
  DrySignals dry;
  dry.samples = {std::vector<float>(4800, 0.f)};
  dry.loop = {0};
  OfflineOptions opt;
  opt.durationSeconds = 0.1;
  opt.bake = loadBakedField(path, s);
  const OfflineResult r = renderOffline(test::shared(s), s.propagation, test::shared(dry), opt);
  REQUIRE(r.bake.bakedResponses > 0);
  REQUIRE(r.listeners.at(0).lastEnergy.size() == 1);
  std::vector<Bands> played = r.listeners[0].lastEnergy[0].bins();
  const DirectSound& direct = r.listeners[0].lastDirect[0];
  played.at(size_t(direct.delaySeconds / 1e-3)) += direct.intensity;
  for (const double seconds : {0.08, 0.5}) {
    Bands sum(0.f);
    for (size_t k = 0; k < played.size() && double(k) * 1e-3 < seconds; ++k) sum += played[k];
    const Bands whole = sumBins(stored, seconds);
    for (int b = 0; b < kNumBands; ++b) CHECK(sum[b] == Approx(whole[b]).epsilon(1e-4));
  }
}
