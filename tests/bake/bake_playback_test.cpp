// Tests for baked playback: loading a bake for a scene (bake/bake_loader.h), the
// visibility-aware interpolation between probes (engine/baked_field.h), its use by the
// propagation stage (runtime/baked_playback.h) and readers' copy of its response
// (runtime/response_snapshot.h).
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <glm/geometric.hpp>

#include "bake/bake_file.h"
#include "bake/bake_loader.h"
#include "bake/hdf5_util.h"
#include "common/input_error.h"
#include "engine/simulation.h"
#include "runtime/live_session.h"
#include "runtime/propagation_stage.h"
#include "runtime/response_snapshot.h"
#include "scene/trajectory.h"
#include "testing/temp_dir.h"
#include "testing/test_scenes.h"
#include "tests/bake/bake_fixtures.h"

using namespace dpc;
using namespace dpc::bake;

namespace {

using dpc::bake::test_fixtures::quickSettings;
using dpc::bake::test_fixtures::shoebox;

/// A complete bake of `scene` on a grid of `spacing` metres at `path`; returns its header.
BakeHeader writeBake(const SceneDesc& scene, const std::string& path, double spacing,
                     bool complete = true) {
  const BakeHeader h = test_fixtures::headerFor(scene, quickSettings(), spacing);
  BakeFile f = BakeFile::create(path, path, h);
  ProbeBaker baker(scene, h.settings);
  for (size_t p = 0; p < h.probes.positions.size(); ++p)
    f.commit(p, baker.bake(p, h.probes.positions[p]));
  if (complete) f.markComplete();
  return h;
}

/// The InputError's field when loading `path` for `scene` (and that it names the file).
std::string refusedField(const std::string& path, const SceneDesc& scene) {
  try {
    loadBakedField(path, scene);
  } catch (const InputError& e) {
    CHECK(e.file() == path);
    CHECK(std::string(e.what()).find('\n') == std::string::npos);
    return e.field().empty() ? std::string(e.what()) : e.field();
  }
  FAIL("no error");
  return "";
}

/// A bake in memory with one source and `bins` bins, each probe's late energy its index + 1
/// in every bin and band (so a blend reveals which probes it used).
std::shared_ptr<BakedField> taggedField(const std::vector<glm::vec3>& probes, size_t bins) {
  auto f = std::make_shared<BakedField>();
  f->probes = probes;
  f->sources = {glm::vec3(2, 1.2f, 1)};
  f->bins = bins;
  for (size_t p = 0; p < probes.size(); ++p) f->late.insert(f->late.end(), bins * 8, float(p + 1));
  fillUniformDirections(*f);
  return f;
}

}  // namespace

TEST_CASE("Baked playback: at a probe the response is that probe's data, direct sound removed",
          "[bake][playback]") {
  test::TempDir dir("bake_play");
  const SceneDesc scene = shoebox();
  const std::string path = (dir.path() / "b.h5").string();
  const BakeHeader h = writeBake(scene, path, 2.5);
  const auto field = loadBakedField(path, scene);
  REQUIRE(field->probes.size() == h.probes.positions.size());
  Simulation sim(scene);
  BakeInterpolator interp(field, sim.tracer());
  const size_t p = 3;
  REQUIRE(interp.locate(h.probes.positions[p]));
  REQUIRE(interp.weights().size() == 1);
  CHECK(interp.weights()[0].probe == p);
  EnergyResponse out(h.settings.irLength, 1e-3);
  interp.response(0, out);
  // The stored response, with its direct sound taken out of the bin of its arrival and its
  // exact early paths (exact_order 3, the default: synthesised live in playback) out of every
  // bin, as the bake stored their part (early/energy), clamped at 0.
  const ProbeResult r = bakeProbe(scene, h.settings, p, h.probes.positions[p]);
  REQUIRE(r.earlyCount[0] > 0);
  std::vector<float> late = r.energy;
  removeDirect(late.data(), out.binCount(), 1e-3, r.directDelay[0], r.directEnergy.data());
  for (size_t i = 0; i < late.size(); ++i) late[i] = std::max(0.f, late[i] - r.earlyEnergy[i]);
  size_t changed = 0;
  for (size_t k = 0; k < out.binCount(); ++k)
    for (int b = 0; b < kNumBands; ++b) {
      CHECK(out.bins()[k][b] == late[k * kNumBands + size_t(b)]);
      changed += late[k * kNumBands + size_t(b)] != r.energy[k * kNumBands + size_t(b)];
    }
  // The direct sound's bin and at least one early path's bin, in every band.
  CHECK(changed >= 2 * kNumBands);
  // The directional split keeps the energy (the direction shares sum to 1): rounding only.
  DirectionalEnergyResponse dirs(h.settings.irLength, 1e-3, defaultSpatialDirections());
  interp.directional(0, dirs);
  for (int b = 0; b < kNumBands; ++b) {
    double sum = 0.0;
    for (size_t j = 0; j < dirs.directionCount(); ++j) sum += dirs.response(j).total()[b];
    CHECK(sum == Approx(out.total()[b]).epsilon(1e-4));
  }
}

// Oracle: a plane wave's first-order density 1 + 3 cos(angle to the wave) (SN3D: f ~ sum_n
// (2n + 1) c_n Y_n), sampled at the synthesiser's directions, puts the energy-weighted mean of
// those directions toward where the wave comes from, for any head orientation. The 8 default
// directions are not uniform (6 on the horizon, one up, one 40 degrees down ahead), so the mean
// is not exactly the wave's direction: within 25 degrees (cos 0.9) of it.
TEST_CASE("Baked playback: the spatial response comes from the baked SH energy's direction",
          "[bake][playback]") {
  const SceneDesc scene = shoebox();
  Simulation sim(scene);
  auto f = taggedField({{5, 1.6f, 3.5f}}, 20);
  const glm::vec3 wave = glm::normalize(glm::vec3(0.3f, 0.1f, 1.f));  // world, toward the wave
  for (size_t j = 0; j < f->directionalBins(); ++j)
    for (int b = 0; b < kNumBands; ++b) {
      // Bake frame (yaw 0): x = world x, y = -world z, z = world y; ACN 1, 2, 3 = y, z, x.
      const float y[4] = {1.f, -wave.z, wave.y, wave.x};
      for (int c = 0; c < 4; ++c) f->sh[(j * 4 + size_t(c)) * kNumBands + size_t(b)] = y[c];
    }
  BakeInterpolator interp(f, sim.tracer());
  REQUIRE(interp.locate({5, 1.6f, 3.5f}));
  for (const float yaw : {0.f, 1.2f, -2.5f}) {
    DirectionalEnergyResponse out(0.02, 1e-3, defaultSpatialDirections());
    out.setListenerFrame({std::cos(yaw), 0.f, -std::sin(yaw)}, {0, 1, 0});
    interp.directional(0, out);
    glm::vec3 mean(0.f);
    double total = 0.0;
    for (size_t k = 0; k < out.directionCount(); ++k) {
      mean += out.toWorld(out.direction(k)) * out.response(k).total()[4];
      total += out.response(k).total()[4];
    }
    CHECK(total == Approx(20.0).epsilon(1e-5));  // 20 bins of 1: every share kept
    CHECK(glm::dot(glm::normalize(mean), wave) > 0.9f);
  }
}

TEST_CASE("Baked playback: between probes the weights are inverse-distance, summing to 1",
          "[bake][playback]") {
  const SceneDesc scene = shoebox();
  Simulation sim(scene);
  BakeInterpolator interp(taggedField({{4, 1.6f, 3.5f}, {6, 1.6f, 3.5f}}, 10), sim.tracer());
  REQUIRE(interp.locate({4.5f, 1.6f, 3.5f}));
  REQUIRE(interp.weights().size() == 2);
  // 1/0.25 : 1/2.25 = 9 : 1.
  CHECK(interp.weights()[0].probe == 0);
  CHECK(interp.weights()[0].weight == Approx(0.9));
  CHECK(interp.weights()[1].weight == Approx(0.1));
  EnergyResponse out(0.01, 1e-3);
  interp.response(0, out);
  CHECK(out.bins()[5][2] == Approx(0.9 * 1 + 0.1 * 2));
}

TEST_CASE("Baked playback: a listener next to a wall never uses a probe on its other side",
          "[bake][playback]") {
  const SceneDesc scene = test::twoRooms(DpcWeighting::kEma, 0.1f);
  Simulation sim(scene);
  // Room A is x < 5, room B x > 5; the wall's doorway is at z 3..4 (door shut).
  const std::vector<glm::vec3> probes = {{5.3f, 1.2f, 1.f}, {5.4f, 1.2f, 2.f}, {2.f, 1.2f, 1.f},
                                         {3.f, 1.2f, 2.f}};
  BakeInterpolator interp(taggedField(probes, 10), sim.tracer());
  for (const glm::vec3 listener : {glm::vec3(4.8f, 1.2f, 1.f), glm::vec3(4.9f, 1.5f, 2.f)}) {
    REQUIRE(interp.locate(listener));
    for (const ProbeWeight& w : interp.weights()) CHECK(probes[w.probe].x < 5.f);
  }
  // Only probes in room B: no visible probe, counted, and the caller plays live.
  BakeInterpolator onlyB(taggedField({probes[0], probes[1]}, 10), sim.tracer());
  CHECK_FALSE(onlyB.locate({4.8f, 1.2f, 1.f}));
  CHECK(onlyB.fallbacks() == 1);
  CHECK(onlyB.located() == 0);
}

TEST_CASE("Baked playback: the stage plays static sources from the bake, moved ones live",
          "[bake][playback]") {
  auto scene = std::make_shared<SceneDesc>(shoebox());
  scene->propagation.raysPerFrame = 500;
  scene->propagation.irLength = 0.5f;
  PropagationStage stage(scene, scene->propagation);
  auto field = taggedField({{8.f, 1.6f, 3.5f}}, 500);
  field->sources = {scene->sources[0].position};
  stage.attachBake(field);
  WorldState world;
  evaluateWorld(*scene, 0.0, world);
  stage.traceWorld(world);
  stage.synthesizeIrs(0);
  REQUIRE(stage.bakedPlayback() != nullptr);
  CHECK(stage.bakedPlayback()->stats().bakedResponses == 1);
  // Played from the bake: not traced; only the listener's proposal rays for the exact paths
  // (exact_order 3), at most 3 segments each.
  CHECK(stage.simulation().skipped(0, 0));
  CHECK(stage.simulation().frameTrace().rays == 500u);
  CHECK(stage.simulation().frameTrace().segments <= 3u * 500u);
  CHECK_FALSE(stage.simulation().specularPaths(0).empty());
  world.sourcePositions[0].x += 0.5f;  // moved: no longer the baked source
  stage.traceWorld(world);
  stage.synthesizeIrs(0);
  CHECK(stage.bakedPlayback()->stats().bakedResponses == 1);
  CHECK(stage.bakedPlayback()->stats().liveResponses == 1);
  CHECK_FALSE(stage.simulation().skipped(0, 0));
  CHECK(stage.simulation().frameTrace().segments > 10u * 500u);  // a full trace
}

// Hybrid mono rendering splits the sources' late shares, reading the bake, in the buses' job
// while the early jobs interpolate the same bake for their early parts: the IRs heard (early
// part plus gain times bus) must be the same bits on 1 to 3 threads, with every source played
// from the bake. A bake read through one shared buffer by both would change them.
TEST_CASE("Baked playback: hybrid mono IRs the same bit for bit on 1 to 3 threads",
          "[bake][playback]") {
  SceneDesc scene = test::ringScene(9);
  scene.audio.output = OutputFormat::kMono;
  scene.audio.rendering = Rendering::kHybrid;
  scene.propagation.raysPerFrame = 500;
  const glm::vec3 listener = scene.listeners[0].position;
  auto field = std::make_shared<BakedField>();
  field->probes = {listener + glm::vec3(0.5f, 0.f, 0.f), listener - glm::vec3(0.f, 0.f, 0.5f)};
  for (const SourceDesc& d : scene.sources) field->sources.push_back(d.position);
  field->bins = size_t(std::lround(scene.propagation.irLength / field->binSeconds));
  // Per probe and source a decay of its own (0.2 s time constant), so a blend mixes them.
  for (size_t p = 0; p < field->probes.size(); ++p)
    for (size_t src = 0; src < field->sources.size(); ++src)
      for (size_t k = 0; k < field->bins; ++k)
        field->late.insert(field->late.end(), kNumBands,
                           float(1e-3 * double(p + 1 + src) * std::exp(-double(k) / 200.0)));
  fillUniformDirections(*field);
  const auto irs = [&](int threads) {
    auto shared = std::make_shared<SceneDesc>(scene);
    shared->propagation.threads = threads;
    PropagationStage stage(shared, shared->propagation);
    REQUIRE(stage.hybrid() != nullptr);
    stage.attachBake(field);
    WorldState world;
    evaluateWorld(*shared, 0.0, world);
    for (int f = 0; f < 3; ++f) stage.traceWorld(world);
    stage.synthesizeIrs(0);
    REQUIRE(stage.bakedPlayback()->stats().bakedResponses >= scene.sources.size());
    return stage.wholeIrs(0);
  };
  const auto one = irs(1);
  REQUIRE(one.size() == scene.sources.size());
  CHECK(irs(2) == one);
  CHECK(irs(3) == one);
}

TEST_CASE("Baked playback: another scene's, an incomplete, a truncated or another version's "
          "bake is refused naming the file and field",
          "[bake][playback]") {
  test::TempDir dir("bake_play_bad");
  const SceneDesc scene = shoebox();
  const std::string path = (dir.path() / "b.h5").string();
  writeBake(scene, path, 5.0);
  SceneDesc other = scene;
  other.mesh.vertices[7].x += 0.5f;
  CHECK(refusedField(path, other) == "hash_geometry");
  const std::string partial = (dir.path() / "partial.h5").string();
  writeBake(scene, partial, 5.0, false);
  CHECK(refusedField(partial, scene) == "complete");
  const std::string cut = (dir.path() / "cut.h5").string();
  std::filesystem::copy_file(path, cut);
  std::filesystem::resize_file(cut, std::filesystem::file_size(path) / 2);
  CHECK_FALSE(refusedField(cut, scene).empty());
  // A newer and an older format (version 2 stored direction as 6 axis energies): refused by
  // name, the older with the reason.
  for (const int64_t version : {int64_t(kBakeFormatVersion + 1), int64_t(2)}) {
    const std::string other = (dir.path() / ("v" + std::to_string(version) + ".h5")).string();
    std::filesystem::copy_file(path, other);
    {
      const h5::Id file(H5Fopen(other.c_str(), H5F_ACC_RDWR, H5P_DEFAULT));
      h5::writeAttribute(file.get(), "version", version);
    }
    CHECK(refusedField(other, scene) == "version");
    try {
      loadBakedField(other, scene);
    } catch (const InputError& e) {
      CHECK(std::string(e.what()).find("format version " + std::to_string(version)) !=
            std::string::npos);
      if (version == 2) CHECK(std::string(e.what()).find("bake again") != std::string::npos);
    }
  }
  // Version 5 is version 6 without the wave band: no hash_wave, its settings_hash over its
  // version and eight groups. Such a file loads, and plays as its version-6 twin.
  const std::string v5 = (dir.path() / "v5.h5").string();
  std::filesystem::copy_file(path, v5);
  {
    const h5::Id file(H5Fopen(v5.c_str(), H5F_ACC_RDWR, H5P_DEFAULT));
    const h5::Id root(H5Gopen2(file.get(), "/", H5P_DEFAULT));
    REQUIRE(H5Adelete(root.get(), "hash_wave") >= 0);
    h5::writeAttribute(root.get(), "version", int64_t(5));
    const BakeFile six = BakeFile::open(path, BakeFile::Access::kRead);
    h5::writeAttribute(root.get(), "settings_hash", combinedHash(six.header().hashes, 5));
  }
  CHECK(loadBakedField(v5, scene)->late == loadBakedField(path, scene)->late);
  // The same file still claiming version 6: its hash_wave is missing.
  {
    const h5::Id file(H5Fopen(v5.c_str(), H5F_ACC_RDWR, H5P_DEFAULT));
    h5::writeAttribute(file.get(), "version", int64_t(6));
  }
  CHECK_THROWS_AS(loadBakedField(v5, scene), InputError);
}

namespace {

/// Energy of source 0's mono IR as the stage last synthesised it (sum of squared samples: the
/// response's energy, docs/design.md "IR synthesis in stages"), after one traced frame.
double irEnergy(PropagationStage& stage, const SceneDesc& scene) {
  WorldState world;
  evaluateWorld(scene, 0.0, world);
  stage.traceWorld(world);
  stage.synthesizeIrs(0);
  double e = 0.0;
  for (const float x : stage.lastIrs()[0].channelSpan(0)) e += double(x) * x;
  return e;
}

}  // namespace

TEST_CASE("Baked playback: the synthesised IR carries the energy of a live one", "[bake][playback]") {
  test::TempDir dir("bake_play_ir");
  auto scene = std::make_shared<SceneDesc>(shoebox());
  scene->propagation.irLength = 0.5f;
  scene->propagation.estimator = Estimator::kPathTracing;
  scene->propagation.raysPerFrame = 20000;
  const std::string path = (dir.path() / "b.h5").string();
  writeBake(*scene, path, 2.5);
  PropagationStage live(scene, scene->propagation);
  PropagationStage baked(scene, scene->propagation);
  baked.attachBake(loadBakedField(path, *scene));
  const double eLive = irEnergy(live, *scene), eBaked = irEnergy(baked, *scene);
  REQUIRE(baked.bakedPlayback()->stats().bakedResponses == 1);
  // The listener (8, 1.6, 3.5) lies between probes 1.25 .. 2.8 m away; the late field of this
  // diffuse box varies by a few tenths of a dB over that distance (dpc-bench bake-interp) and
  // the bake's 2000 rays per probe add about 0.2 dB of Monte Carlo error: 1 dB is the
  // issue's target and 5 times that spread. The direct sound is the same live one in both.
  CHECK(10.0 * std::log10(eBaked / eLive) == Approx(0.0).margin(1.0));
}

TEST_CASE("Baked playback: the spatial (stereo) synthesis plays the bake's directions too",
          "[bake][playback]") {
  test::TempDir dir("bake_play_stereo");
  auto scene = std::make_shared<SceneDesc>(shoebox());
  scene->propagation.irLength = 0.5f;
  scene->propagation.estimator = Estimator::kPathTracing;
  scene->propagation.raysPerFrame = 20000;
  scene->audio.output = OutputFormat::kStereo;
  const std::string path = (dir.path() / "b.h5").string();
  writeBake(*scene, path, 2.5);
  PropagationStage live(scene, scene->propagation), baked(scene, scene->propagation);
  baked.attachBake(loadBakedField(path, *scene));
  auto energy = [&](PropagationStage& stage) {
    WorldState world;
    evaluateWorld(*scene, 0.0, world);
    stage.traceWorld(world);
    stage.synthesizeIrs(0);
    double e = 0.0;
    for (const float x : stage.lastIrs()[0].data()) e += double(x) * x;
    return e;
  };
  const double eLive = energy(live), eBaked = energy(baked);
  REQUIRE(baked.bakedPlayback()->stats().bakedResponses == 1);
  // As for mono: the late field's spread over the probes' distances plus the bake's Monte
  // Carlo error stay well inside 1 dB; the panning keeps energy (constant-power gains).
  CHECK(10.0 * std::log10(eBaked / eLive) == Approx(0.0).margin(1.0));
}

TEST_CASE("Baked playback: a source leaving its baked position switches back to the DPC at the "
          "same level",
          "[bake][playback]") {
  test::TempDir dir("bake_play_switch");
  auto scene = std::make_shared<SceneDesc>(shoebox());
  scene->propagation.irLength = 0.5f;
  scene->propagation.raysPerFrame = 20000;  // the DPC (window), restarted on the switch
  const std::string path = (dir.path() / "b.h5").string();
  writeBake(*scene, path, 2.5);
  PropagationStage stage(scene, scene->propagation);
  stage.attachBake(loadBakedField(path, *scene));
  WorldState world;
  evaluateWorld(*scene, 0.0, world);
  auto frame = [&] {
    stage.traceWorld(world);
    stage.synthesizeIrs(0);
    double e = 0.0;
    for (const float x : stage.lastIrs()[0].channelSpan(0)) e += double(x) * x;
    return e;
  };
  double eBaked = 0.0;
  for (int f = 0; f < 3; ++f) eBaked = frame();
  REQUIRE(stage.simulation().skipped(0, 0));
  world.sourcePositions[0].z += 0.02f;  // 2 cm: beyond the 1 cm of a static source
  const double eLive = frame();
  REQUIRE_FALSE(stage.simulation().skipped(0, 0));
  CHECK(stage.bakedPlayback()->stats().liveResponses == 1);
  // The restarted cache's first frame is one frame of plain path tracing (20000 rays: its
  // late energy is within a few hundredths of a dB of its expectation) and the source moved
  // 2 cm: the step is the baked-vs-live difference of the test above, within its 1 dB.
  CHECK(10.0 * std::log10(eLive / eBaked) == Approx(0.0).margin(1.0));
}

namespace {

/// Source 0's energy response, its origin, its direct sound and its exact early paths as the
/// snapshot holds them.
struct SnapshotRead {
  std::vector<Bands> energy;
  bool fromBake = false;
  DirectSound direct;
  std::vector<SpecularPath> paths;
};

SnapshotRead readSnapshot(ResponseSnapshot& snapshot) {
  SnapshotRead out;
  REQUIRE(snapshot.read(0, [&](const ResponseSnapshot::Responses& r) {
    out.energy = *r.energy;
    out.fromBake = r.fromBake;
    out.direct = *r.direct;
    out.paths = *r.paths;
  }));
  return out;
}

/// `bins` with the read's direct sound and exact paths added in the 1 ms bins of their delays.
std::vector<Bands> withArrivals(std::vector<Bands> bins, const SnapshotRead& read) {
  const auto add = [&](double delay, const Bands& e) {
    if (delay >= 0.0 && size_t(delay / 1e-3) < bins.size()) bins[size_t(delay / 1e-3)] += e;
  };
  add(read.direct.delaySeconds, read.direct.intensity);
  for (const SpecularPath& p : read.paths) add(p.delaySeconds, p.intensity);
  return bins;
}

}  // namespace

// What readers of a frame (the C API's copy, dpc studio's decay panel) get of a pair played
// from the bake. Oracle: the bake the test built (every late bin 1 at the listener's probe,
// taken alone there) plus the live direct sound and the live exact paths in their bins, what
// the IR is synthesised from; once the source moves, the simulation's own traced result with
// the same arrivals. On a snapshot that ignored the bake the first check sees the arrivals
// alone; on one that left the exact paths out, their bins are short.
TEST_CASE("Baked playback: the response snapshot carries the bake's response, labelled",
          "[bake][playback]") {
  auto scene = std::make_shared<SceneDesc>(shoebox());
  scene->propagation.raysPerFrame = 500;
  scene->propagation.irLength = 0.5f;
  PropagationStage stage(scene, scene->propagation);
  WorldState world;
  evaluateWorld(*scene, 0.0, world);
  auto field = taggedField({world.listenerPositions[0]}, 500);  // a probe at the listener
  field->sources = {scene->sources[0].position};
  stage.attachBake(field);
  ResponseSnapshot snapshot;
  const auto frame = [&] {
    stage.traceWorld(world);
    stage.synthesizeIrs(0);
    REQUIRE(snapshot.tryStore(stage, world, 0, stage.totals().frames));
    return readSnapshot(snapshot);
  };
  const SnapshotRead baked = frame();
  CHECK(baked.fromBake);
  REQUIRE(baked.energy.size() == 500);
  REQUIRE(baked.direct.visible);
  REQUIRE(!baked.paths.empty());  // the shoebox's exact_order finds some
  const std::vector<Bands> bakedWant = withArrivals(std::vector<Bands>(500, Bands(1.f)), baked);
  for (size_t k = 0; k < baked.energy.size(); ++k)
    for (int b = 0; b < kNumBands; ++b) CHECK(baked.energy[k][b] == Approx(bakedWant[k][b]));
  world.sourcePositions[0].x += 0.5f;  // moved: traced again
  const SnapshotRead traced = frame();
  CHECK_FALSE(traced.fromBake);
  const std::vector<Bands> want =
      withArrivals(stage.simulation().result(0, 0).energy.bins(), traced);
  REQUIRE(traced.energy.size() == want.size());
  for (size_t k = 0; k < want.size(); ++k)
    for (int b = 0; b < kNumBands; ++b) CHECK(traced.energy[k][b] == Approx(want[k][b]));
  CHECK(traced.energy != baked.energy);
}

namespace {

/// `f` given a wave band for a scene at `fs` Hz (maximum 250 Hz, crossover 125 Hz): probe k's
/// band a unit impulse at sample 24 (k + 1), so the probes' bands tell them apart; `reached`
/// per probe.
void addWave(BakedField& f, int fs, size_t samples, const std::vector<uint8_t>& reached) {
  f.waveSamples = samples;
  f.waveSampleRate = fs;
  f.waveMaxFrequencyHz = 250.0;
  f.waveCrossoverHz = 125.0;
  f.waveReached = reached;
  f.wave.assign(f.probes.size() * samples, 0.f);
  for (size_t p = 0; p < f.probes.size(); ++p) f.wave[p * samples + 24 * (p + 1)] = 1.f;
}

/// Source 0's IR (channel 0) for the listener at `at` after one frame.
std::vector<float> irAt(PropagationStage& stage, const SceneDesc& scene, const glm::vec3& at) {
  WorldState world;
  evaluateWorld(scene, 0.0, world);
  world.listenerPositions[0] = at;
  stage.traceWorld(world);
  stage.synthesizeIrs(0);
  const auto x = stage.lastIrs()[0].channelSpan(0);
  return {x.begin(), x.end()};
}

}  // namespace

TEST_CASE("Baked playback: a bake's wave band joins each baked pair's IR, blended between the "
          "probes as the late response is, and a live session plays it",
          "[bake][playback][wave]") {
  auto scene = std::make_shared<SceneDesc>(shoebox());
  scene->propagation.raysPerFrame = 500;
  scene->wave.enabled = true;
  scene->wave.maxFrequencyHz = 250.f;
  const int fs = scene->audio.sampleRate;
  const size_t samples = size_t(std::llround(scene->propagation.irLength * fs));
  const std::vector<glm::vec3> probes = {{8.f, 1.6f, 3.5f}, {6.f, 1.6f, 3.5f}, {4.f, 1.6f, 3.5f}};
  auto plain = taggedField(probes, 500);
  plain->sources = {scene->sources[0].position};
  auto waved = std::make_shared<BakedField>(*plain);
  addWave(*waved, fs, samples, {1, 1, 0});
  // Oracle: the same bake without its wave band, joined instead with one band by the offline
  // renderer's path (attachWaveBands): `weights` (probe, weight) summed into it beforehand.
  auto joinedWith = [&](const std::vector<std::pair<size_t, double>>& weights,
                        const glm::vec3& at) {
    PropagationStage stage(scene, scene->propagation);
    stage.attachBake(plain);
    auto set = std::make_shared<wave::WaveBandSet>(1, 1, scene->audio.output, 125.0, 250.0,
                                                   double(fs));
    std::vector<float> band(samples, 0.f);
    for (const auto& [probe, w] : weights)
      for (size_t i = 0; i < samples; ++i) band[i] += float(w * waved->wave[probe * samples + i]);
    set->set(0, 0, band);
    stage.attachWaveBands(set);
    return irAt(stage, *scene, at);
  };
  // Largest difference over the peak: float rounding of one low-pass of the sum against the
  // sum of the low-passed bands is about 1e-7 of the peak (the test allows 1e-6).
  auto apart = [](const std::vector<float>& a, const std::vector<float>& b) {
    double diff = 0.0, peak = 0.0;
    for (size_t i = 0; i < a.size(); ++i) {
      diff = std::max(diff, double(std::abs(a[i] - b[i])));
      peak = std::max(peak, double(std::abs(b[i])));
    }
    return diff / peak;
  };
  // Each IR from a fresh stage's first frame (a frame's synthesis draws from its frame).
  auto playedAt = [&](const std::shared_ptr<BakedField>& field, const glm::vec3& at) {
    PropagationStage stage(scene, scene->propagation);
    stage.attachBake(field);
    std::vector<float> ir = irAt(stage, *scene, at);
    CHECK(stage.bakedPlayback()->stats().bakedResponses == 1);
    return ir;
  };
  // On probe 0: that probe's band alone, the same bits.
  CHECK(playedAt(waved, probes[0]) == joinedWith({{0, 1.0}}, probes[0]));
  // Between probes 0 and 1 (1.2 and 0.8 m), probe 2 (2.8 m) visible but unreached: Shepard's
  // 1 / d^2 weights of the late response (engine/baked_field.h), renormalised over probes 0
  // and 1.
  const glm::vec3 between{6.8f, 1.6f, 3.5f};
  const double w0 = 1.0 / (1.2 * 1.2), w1 = 1.0 / (0.8 * 0.8);
  const std::vector<float> blended = playedAt(waved, between);
  CHECK(apart(blended, joinedWith({{0, w0 / (w0 + w1)}, {1, w1 / (w0 + w1)}}, between)) <=
        1e-6);  // measured 5e-8
  // The check can fail: the nearest probe's band alone lies 2e-4 of the peak away (the peak is
  // the direct sound's; the bands are small beside it).
  CHECK(apart(blended, joinedWith({{1, 1.0}}, between)) > 1e-5);
  // Probe 2 lies outside the air its grid reached: a listener on it gets no wave band.
  CHECK(playedAt(waved, probes[2]) == playedAt(plain, probes[2]));

  // Live: wave.enabled is refused without a bake that carries the band, played with one.
  DrySignals dry;
  dry.samples = {std::vector<float>(4800, 0.f)};
  dry.loop = {1};
  LiveSession::Options o;
  CHECK_THROWS_AS(LiveSession(scene, scene->propagation, test::shared(dry), o), InputError);
  o.bake = waved;
  LiveSession session(scene, scene->propagation, test::shared(dry), o);
  REQUIRE(session.step());
  CHECK(session.status().bakedResponses == 1);
}
