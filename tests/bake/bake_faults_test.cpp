// A bake file that cannot lie (bake/bake_file.h, bake/settings_hash.h): faults a user's disk,
// a crash or a writer's bug leave in a file are refused at open, or found by --resume's
// inspection and baked again; never played. Each fault is made in the file with HDF5 or by
// flipping its bytes, then opened as playback (loadBakedField) and --resume (kInspect) do.
#include <hdf5.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>

#include "bake/bake_file.h"
#include "bake/bake_loader.h"
#include "bake/hdf5_util.h"
#include "bake/settings_hash.h"
#include "common/input_error.h"
#include "testing/temp_dir.h"
#include "tests/bake/bake_fixtures.h"

using namespace dpc;
using namespace dpc::bake;
using test_fixtures::headerFor;
using test_fixtures::quickSettings;
using test_fixtures::shoebox;

namespace {

/// A bake of the shoebox at 5 m (2 probes) at `path`, every probe committed but `skip`
/// (SIZE_MAX: none), complete when asked and all are stored.
BakeHeader writeBake(const std::string& path, size_t skip = SIZE_MAX, bool complete = true) {
  const SceneDesc scene = shoebox();
  const BakeHeader h = headerFor(scene, quickSettings(), 5.0);
  BakeFile f = BakeFile::create(path, path, h);
  ProbeBaker baker(scene, h.settings);
  for (size_t p = 0; p < h.probes.positions.size(); ++p)
    if (p != skip) f.commit(p, baker.bake(p, h.probes.positions[p]));
  if (complete) f.markComplete();
  return h;
}

/// The one-line refusal loading `path` for playback gives, "" when it loads.
std::string refusal(const std::string& path, const SceneDesc& scene) {
  try {
    loadBakedField(path, scene);
  } catch (const InputError& e) {
    CHECK(e.file() == path);
    CHECK(std::string(e.what()).find('\n') == std::string::npos);
    return e.what();
  }
  return "";
}

std::vector<char> bytesOf(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<char>(std::istreambuf_iterator<char>(in), {});
}

void writeBytes(const std::string& path, const std::vector<char>& b) {
  std::ofstream(path, std::ios::binary).write(b.data(), std::streamsize(b.size()));
}

/// Sets an attribute or writes dataset rows of a closed bake with HDF5 directly (a writer's
/// bug, not dpc's writer).
void setComplete(const std::string& path, int64_t value) {
  const h5::Id f(H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT));
  REQUIRE(f.valid());
  h5::writeAttribute(f.get(), "complete", value);
}

/// The bits of floats (NaN parameters compare equal to themselves).
std::vector<uint32_t> bits(const std::vector<float>& v) {
  std::vector<uint32_t> b(v.size());
  if (!v.empty()) std::memcpy(b.data(), v.data(), v.size() * sizeof(float));
  return b;
}

/// Everything a reader gets from a bake: every float dataset, the done mask and the header.
std::vector<std::vector<uint64_t>> contents(const std::string& path) {
  const BakeFile f = BakeFile::open(path, BakeFile::Access::kRead);
  std::vector<std::vector<uint64_t>> all;
  auto add = [&all](const std::vector<uint32_t>& v) { all.emplace_back(v.begin(), v.end()); };
  for (const ProbeDataset& d : kProbeDatasets) add(bits(f.readAll(d.name)));
  for (const char* d : {"probes/position", "sources/position", "band_centres_hz"})
    add(bits(f.readAll(d)));
  all.emplace_back(f.done().begin(), f.done().end());
  const BakeHeader& h = f.header();
  all.push_back({uint64_t(f.complete()), uint64_t(h.settings.rays), uint64_t(h.settings.frames),
                 bits({float(h.settings.irLength), h.grid.radiusM})[0], h.seed,
                 h.probes.candidates, h.probes.outside});
  all.emplace_back(h.hashes.begin(), h.hashes.end());
  return all;
}

}  // namespace

TEST_CASE("Bake faults: a probe never written yet marked complete is refused at open",
          "[bake][faults]") {
  test::TempDir dir("bake_faults_missing");
  const SceneDesc scene = shoebox();
  const std::string path = (dir.path() / "b.h5").string();
  // dpc's writer does not mark it complete (markComplete verifies first)...
  writeBake(path, 0, false);
  {
    BakeFile f = BakeFile::open(path, BakeFile::Access::kWrite);
    CHECK_THROWS_AS(f.markComplete(), InputError);
  }
  CHECK(refusal(path, scene).find("complete: the bake is incomplete") != std::string::npos);
  // ... and a file that says complete anyway is refused, naming the probe.
  setComplete(path, 1);
  CHECK(refusal(path, scene).find(path + ": probes/done: probe 0 is not stored") == 0);
  // Marked done, its rows never written: its checksums do not match.
  {
    const h5::Id f(H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT));
    const uint8_t one = 1;
    h5::writeRows(f.get(), "probes/done", H5T_NATIVE_UINT8, 0, 1, &one);
  }
  CHECK(refusal(path, scene).find(path + ": /energy: probe 0: CRC-32") == 0);
  // --resume's inspection counts it as damaged, not done, and bakes it again.
  const BakeFile f = BakeFile::open(path, BakeFile::Access::kInspect);
  CHECK(f.damaged() == std::vector<size_t>{0});
  CHECK(f.done()[0] == 0);
  CHECK(f.done()[1] == 1);
}

TEST_CASE("Bake faults: 300 flipped bytes at random offsets are refused, for every seed",
          "[bake][faults]") {
  test::TempDir dir("bake_faults_flips");
  const SceneDesc scene = shoebox();
  const std::string path = (dir.path() / "b.h5").string();
  writeBake(path);
  REQUIRE(refusal(path, scene).empty());
  const std::vector<char> clean = bytesOf(path);
  const std::string bad = (dir.path() / "bad.h5").string();
  int refused = 0;
  for (uint64_t seed = 1; seed <= 8; ++seed) {
    std::mt19937_64 rng(seed);
    std::vector<char> b = clean;
    for (int i = 0; i < 300; ++i) b[rng() % b.size()] ^= char(1 << (rng() % 8));
    writeBytes(bad, b);
    refused += !refusal(bad, scene).empty();
  }
  CHECK(refused == 8);
}

/// [offset, offset + size) of every dataset's stored bytes in the file (contiguous).
std::vector<std::pair<size_t, size_t>> datasetExtents(const std::string& path) {
  std::vector<std::string> names = {"probes/position", "probes/done", "sources/position",
                                    "band_centres_hz", "checksums"};
  for (const ProbeDataset& d : kProbeDatasets) names.push_back(d.name);
  const h5::Id f(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT));
  std::vector<std::pair<size_t, size_t>> out;
  for (const std::string& n : names) {
    const h5::Id set(H5Dopen2(f.get(), n.c_str(), H5P_DEFAULT));
    const size_t at = size_t(H5Dget_offset(set.get()));
    out.emplace_back(at, at + size_t(H5Dget_storage_size(set.get())));
  }
  return out;
}

TEST_CASE("Bake faults: one flipped byte anywhere is refused or changes nothing read",
          "[bake][faults]") {
  // Every byte of a dataset is under dpc's CRC-32s, every byte of HDF5's metadata under HDF5's
  // own checksums; only bytes HDF5 leaves unused (padding between its metadata blocks) carry
  // nothing, and flipping one of them must change nothing a reader gets.
  test::TempDir dir("bake_faults_flip");
  const SceneDesc scene = shoebox();
  const std::string path = (dir.path() / "b.h5").string();
  writeBake(path);
  const std::vector<char> clean = bytesOf(path);
  const auto reference = contents(path);
  const auto extents = datasetExtents(path);
  const std::string bad = (dir.path() / "bad.h5").string();
  std::mt19937_64 rng(7);
  int refused = 0, inData = 0, unchanged = 0;
  for (int i = 0; i < 400; ++i) {
    std::vector<char> b = clean;
    // Half the flips in the first 8 kB, where HDF5's metadata lies.
    const size_t at = i % 2 ? rng() % b.size() : rng() % std::min<size_t>(8192, b.size());
    b[at] ^= char(1 << (rng() % 8));
    writeBytes(bad, b);
    const bool data = std::any_of(extents.begin(), extents.end(),
                                  [at](const auto& e) { return at >= e.first && at < e.second; });
    inData += data;
    INFO("byte " << at << " flipped" << (data ? ", inside a dataset" : ""));
    if (!refusal(bad, scene).empty()) {
      ++refused;
    } else {
      REQUIRE_FALSE(data);
      REQUIRE(contents(bad) == reference);
      ++unchanged;
    }
  }
  WARN(refused << " of 400 single flips refused (" << inData << " inside datasets), "
               << unchanged << " in unused bytes, changing nothing");
  CHECK(inData > 100);  // the uniform half lands mostly in the data: the case is exercised
}

TEST_CASE("Bake faults: a truncated bake is refused at any length", "[bake][faults]") {
  test::TempDir dir("bake_faults_cut");
  const SceneDesc scene = shoebox();
  const std::string path = (dir.path() / "b.h5").string();
  writeBake(path);
  const std::vector<char> clean = bytesOf(path);
  const std::string cut = (dir.path() / "cut.h5").string();
  for (const size_t n : {size_t(0), size_t(8), size_t(100), size_t(2048), clean.size() / 4,
                         clean.size() / 2, clean.size() * 3 / 4, clean.size() - 4096,
                         clean.size() - 1}) {
    writeBytes(cut, std::vector<char>(clean.begin(), clean.begin() + std::ptrdiff_t(n)));
    INFO("truncated to " << n << " of " << clean.size() << " bytes");
    CHECK_FALSE(refusal(cut, scene).empty());
  }
}

TEST_CASE("Bake faults: a damaged probe is baked again by --resume, the others kept",
          "[bake][faults]") {
  test::TempDir dir("bake_faults_resume");
  const std::string path = (dir.path() / "b.h5").string();
  const BakeHeader h = writeBake(path);
  // Flip a byte inside probe 1's row of sh_energy (contiguous: offset + row * row bytes).
  size_t offset = 0;
  {
    const h5::Id f(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT));
    const h5::Id set(H5Dopen2(f.get(), "sh_energy", H5P_DEFAULT));
    const size_t row = h.shape.shFloats() * sizeof(float);
    offset = size_t(H5Dget_offset(set.get())) + row + row / 2;
  }
  std::vector<char> b = bytesOf(path);
  b[offset] ^= 0x40;
  writeBytes(path, b);
  CHECK(refusal(path, shoebox()).find(path + ": /sh_energy: probe 1: CRC-32") == 0);
  const BakeFile f = BakeFile::open(path, BakeFile::Access::kInspect);
  CHECK(f.damaged() == std::vector<size_t>{1});
  CHECK(f.done() == std::vector<uint8_t>{1, 0});
}

TEST_CASE("Bake faults: the settings hash sees every setting that changes a probe, in its group",
          "[bake][faults]") {
  const SceneDesc a = shoebox();
  const BakeSettings s = quickSettings();
  const std::vector<glm::vec3> probes = {{5.f, 1.6f, 3.5f}};
  const SettingsHash base = settingsHash(a, s, probes);
  auto changedGroups = [&](const SceneDesc& b, const BakeSettings& t,
                           const std::vector<glm::vec3>& q) {
    const SettingsHash h = settingsHash(b, t, q);
    std::set<int> groups;
    for (int g = 0; g < kSettingGroups; ++g)
      if (h[size_t(g)] != base[size_t(g)]) groups.insert(g);
    return groups;
  };
  auto only = [](SettingGroup g) { return std::set<int>{int(g)}; };
  SceneDesc b = a;
  b.mesh.vertices[7].x += 0.01f;
  CHECK(changedGroups(b, s, probes) == only(SettingGroup::kGeometry));
  b = a;
  b.materials[0].absorption[3] = 0.3f;
  CHECK(changedGroups(b, s, probes) == only(SettingGroup::kMaterials));
  b = a;
  b.materials[0].scattering[0] = 0.9f;
  CHECK(changedGroups(b, s, probes) == only(SettingGroup::kMaterials));
  b = a;
  b.materials[0].transmissionLossDb = Bands(30.f);
  CHECK(changedGroups(b, s, probes) == only(SettingGroup::kMaterials));
  b = a;
  b.sources[0].position.z += 1.f;
  CHECK(changedGroups(b, s, probes) == only(SettingGroup::kSources));
  b = a;
  b.sources[0].directivity.a = Bands(0.5f);
  CHECK(changedGroups(b, s, probes) == only(SettingGroup::kSources));
  b = a;
  b.sources[0].rotation = glm::quat(0.f, 0.f, 1.f, 0.f);
  CHECK(changedGroups(b, s, probes) == only(SettingGroup::kSources));
  b = a;
  b.listeners[0].radius = 0.4f;
  CHECK(changedGroups(b, s, probes) == only(SettingGroup::kListener));
  for (auto change : {+[](PropagationSettings& p) { p.exactOrder = 1; },
                      +[](PropagationSettings& p) { p.maxOrder = 10; },
                      +[](PropagationSettings& p) { p.temperatureC = 30.f; },
                      +[](PropagationSettings& p) { p.airAbsorption = false; },
                      +[](PropagationSettings& p) { p.diffraction = false; },
                      +[](PropagationSettings& p) { p.speedOfSound = 340.f; }}) {
    b = a;
    change(b.propagation);
    CHECK(changedGroups(b, s, probes) == only(SettingGroup::kPhysics));
  }
  b = a;
  b.propagation.seed = 2;
  CHECK(changedGroups(b, s, probes) == only(SettingGroup::kSampling));
  b = a;
  b.propagation.patchSize = 0.25f;  // groups the hits whose directions sh_energy sums
  CHECK(changedGroups(b, s, probes) == only(SettingGroup::kSampling));
  BakeSettings t = s;
  t.rays = 501;
  CHECK(changedGroups(a, t, probes) == only(SettingGroup::kSampling));
  t = s;
  t.frames = 8;
  CHECK(changedGroups(a, t, probes) == only(SettingGroup::kSampling));
  t = s;
  t.irLength = 1.0;
  CHECK(changedGroups(a, t, probes) == only(SettingGroup::kResponse));
  CHECK(changedGroups(a, s, {{5.f, 1.6f, 3.6f}}) == only(SettingGroup::kProbes));
  // The wave band: on, and each of its keys (and the rate it is stored at) once it is on.
  b = a;
  b.wave.enabled = true;
  CHECK(changedGroups(b, s, probes) == only(SettingGroup::kWave));
  SceneDesc w = b;
  for (auto change : {+[](SceneDesc& x) { x.wave.maxFrequencyHz = 300.f; },
                      +[](SceneDesc& x) { x.wave.crossoverHz = 100.f; },
                      +[](SceneDesc& x) { x.wave.gridSpacingM = 0.1f; },
                      +[](SceneDesc& x) { x.audio.sampleRate = 44100; }}) {
    w = b;
    change(w);
    const SettingsHash h = settingsHash(w, s, probes), base = settingsHash(b, s, probes);
    CHECK(h[size_t(SettingGroup::kWave)] != base[size_t(SettingGroup::kWave)]);
  }
  // Settings that do not change a probe: no group.
  b = a;
  b.propagation.cacheTau = 0.2f;
  b.propagation.estimator = Estimator::kPathTracing;
  b.propagation.frameRate = 30.f;
  b.propagation.raysPerFrame = 17;
  b.propagation.threads = 3;
  b.audio.sampleRate = 44100;
  b.audio.output = OutputFormat::kStereo;
  b.sources[0].gainDb = -6.f;
  t = s;
  t.threads = 2;
  CHECK(changedGroups(b, t, probes).empty());
}

TEST_CASE("Bake faults: playback refuses a bake of other content, accepts another sample of it",
          "[bake][faults]") {
  test::TempDir dir("bake_faults_play");
  const std::string path = (dir.path() / "b.h5").string();
  writeBake(path);
  const SceneDesc a = shoebox();
  SceneDesc b = a;
  b.propagation.irLength = 1.0f;
  CHECK(refusal(path, b).find(path + ": ir_length_s: the bake's responses are 0.5") == 0);
  b = a;
  b.materials[0].transmissionLossDb = Bands(30.f);
  CHECK(refusal(path, b).find(path + ": hash_materials:") == 0);
  b = a;
  b.propagation.exactOrder = 0;
  CHECK(refusal(path, b).find(path + ": hash_physics:") == 0);
  b = a;
  b.sources[0].directivity.a = Bands(0.5f);
  CHECK(refusal(path, b).find(path + ": hash_sources:") == 0);
  // Another seed, another listener radius, rays or cache settings: the same responses, drawn
  // again; the bake plays.
  b = a;
  b.propagation.seed = 9;
  b.listeners[0].radius = 0.3f;
  b.propagation.raysPerFrame = 100;
  b.propagation.cacheTau = 0.2f;
  CHECK(refusal(path, b).empty());
}
