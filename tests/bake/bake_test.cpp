// Tests for dpc-bake's parts (apps/bake): probe placement, the determinism of a probe, and the
// HDF5 file's round trip, validation and refusal of damaged or foreign files.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "bake/bake_file.h"
#include "bake/probe_bake.h"
#include "bake/probe_grid.h"
#include "common/input_error.h"
#include "testing/temp_dir.h"
#include "testing/test_scenes.h"
#include "tests/bake/bake_fixtures.h"

using namespace dpc;
using namespace dpc::bake;

namespace {

/// A 10 x 3 x 7 m box with a closed 2 x 3 x 2 m pillar at x 4..6, z 2..4 (its faces outward).
SceneDesc roomWithPillar() {
  SceneDesc s = test::makeShoebox({10.f, 3.f, 7.f}, Bands(0.2f), 0.5f, {2.f, 1.6f, 1.f},
                                  {8.f, 1.6f, 5.f});
  const uint32_t base = uint32_t(s.mesh.vertices.size());
  for (int i = 0; i < 8; ++i)
    s.mesh.vertices.push_back({(i & 1) ? 6.f : 4.f, (i & 2) ? 3.f : 0.f, (i & 4) ? 4.f : 2.f});
  const int quads[6][4] = {{0, 1, 3, 2}, {4, 6, 7, 5}, {0, 4, 5, 1},
                           {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 5, 7, 3}};
  for (const auto& q : quads) {
    s.mesh.triangles.push_back({base + q[0], base + q[1], base + q[2]});
    s.mesh.triangles.push_back({base + q[0], base + q[2], base + q[3]});
  }
  s.mesh.materialIndex.assign(s.mesh.triangles.size(), 0);
  return s;
}

/// Bit-identical float arrays (NaN included, which == would call unequal).
bool sameBits(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

using dpc::bake::test_fixtures::quickSettings;
using dpc::bake::test_fixtures::shoebox;

using dpc::bake::test_fixtures::headerFor;

}  // namespace

TEST_CASE("Bake grid: cell centres in a closed box, all kept", "[bake]") {
  const ProbeGrid g = makeProbeGrid(shoebox(), GridRequest{1.0, 1.6, 0.5f}, "box.json");
  CHECK(g.candidates == 70);
  CHECK(g.positions.size() == 70);
  CHECK(g.positions.front().x == Approx(0.5));
  CHECK(g.positions.front().y == Approx(1.6));
  CHECK(g.positions.back().z == Approx(6.5));
}

TEST_CASE("Bake box: a 3-D lattice centred in the box, layers in height, all inside it",
          "[bake]") {
  // The 10 x 3 x 7 m room, a box over its middle, 1 m spacing.
  GridRequest r{1.0, 0.0, 0.5f};
  r.box = true;
  r.boxMin = {2.f, 0.9f, 1.5f};
  r.boxMax = {8.f, 2.1f, 5.5f};
  const ProbeGrid g = makeProbeGrid(shoebox(), r, "box.json");
  // floor(6/1) x floor(1.2/1) x floor(4/1) = 6 x 1 x 4 points, each axis centred in the box.
  CHECK(g.candidates == 24);
  CHECK(g.positions.size() == 24);
  CHECK(g.positions.front().x == Approx(2.5));
  CHECK(g.positions.front().y == Approx(1.5));  // one layer: the box's middle
  CHECK(g.positions.front().z == Approx(2.0));
  CHECK(g.positions.back().x == Approx(7.5));
  CHECK(g.positions.back().z == Approx(5.0));
  // Two layers when the box is two spacings tall: y = 0.75 and 1.75 m.
  r.boxMin.y = 0.25f;
  r.boxMax.y = 2.25f;
  const ProbeGrid tall = makeProbeGrid(shoebox(), r, "box.json");
  CHECK(tall.candidates == 48);
  CHECK(tall.positions.front().y == Approx(0.75));
  CHECK(tall.positions.back().y == Approx(1.75));
  CHECK(probeLayout(r, false) == "box 2 0.25 1.5 8 2.25 5.5");
  // A box reaching outside the room keeps only the points inside, and counts the others.
  r.boxMin = {-5.f, 1.f, 1.f};
  r.boxMax = {5.f, 2.f, 6.f};
  const ProbeGrid half = makeProbeGrid(shoebox(), r, "box.json");
  CHECK(half.outside > 0);
  CHECK(half.positions.size() + half.outside + half.insideGeometry + half.nearSurface ==
        half.candidates);
  for (const glm::vec3& p : half.positions) CHECK(p.x > 0.f);
}

TEST_CASE("Bake box: corners that are not a box name --box", "[bake]") {
  GridRequest r{1.0, 0.0, 0.5f};
  r.box = true;
  const std::vector<std::pair<glm::vec3, glm::vec3>> bad = {
      {{2, 1, 1}, {2, 2, 2}},                   // no x extent
      {{2, 2, 1}, {3, 1, 2}},                   // y reversed
      {{2, 1, 1}, {std::nanf(""), 2, 2}},       // NaN
      {{2, 1, 1}, {3, 2, 2e7f}}};               // beyond the scene limits
  for (const auto& [lo, hi] : bad) {
    r.boxMin = lo;
    r.boxMax = hi;
    try {
      makeProbeGrid(shoebox(), r, "box.json");
      FAIL("no error");
    } catch (const InputError& e) {
      CHECK(e.field() == "--box");
    }
  }
}

TEST_CASE("Bake grid: probes inside a pillar and near its faces are skipped and counted",
          "[bake]") {
  const ProbeGrid g = makeProbeGrid(roomWithPillar(), GridRequest{1.0, 1.6, 0.5f}, "p.json");
  // Cell centres inside the pillar: x in {4.5, 5.5}, z in {2.5, 3.5}.
  CHECK(g.insideGeometry == 4);
  // The candidate count adds up, and no kept probe lies inside the pillar.
  CHECK(g.positions.size() + g.outside + g.insideGeometry + g.nearSurface == g.candidates);
  for (const glm::vec3& p : g.positions) CHECK_FALSE((p.x > 4 && p.x < 6 && p.z > 2 && p.z < 4));
  // A radius larger than half the spacing keeps only probes farther than it from every face.
  const ProbeGrid wide = makeProbeGrid(roomWithPillar(), GridRequest{1.0, 1.6, 0.8f}, "p.json");
  CHECK(wide.nearSurface > 0);
}

TEST_CASE("Bake grid: bad spacing and empty grids name the flag", "[bake]") {
  for (const double spacing : {0.0, -1.0, std::nan("")}) {
    try {
      makeProbeGrid(shoebox(), GridRequest{spacing, 1.6, 0.5f}, "box.json");
      FAIL("no error");
    } catch (const InputError& e) {
      CHECK(e.field() == "--spacing");
    }
  }
  // A spacing larger than the room: no cell centre at all.
  CHECK_THROWS_AS(makeProbeGrid(shoebox(), GridRequest{20.0, 1.6, 0.5f}, "box.json"), InputError);
  // Above the ceiling: every candidate is outside.
  try {
    makeProbeGrid(shoebox(), GridRequest{1.0, 5.0, 0.5f}, "box.json");
    FAIL("no error");
  } catch (const InputError& e) {
    CHECK(e.file() == "box.json");
    CHECK(std::string(e.what()).find("70 outside") != std::string::npos);
  }
}

TEST_CASE("Bake probe: the result depends only on the probe index, not on thread count",
          "[bake]") {
  const SceneDesc scene = shoebox();
  BakeSettings one = quickSettings(), two = quickSettings();
  two.threads = 2;
  const glm::vec3 p(5.f, 1.6f, 3.5f);
  const ProbeResult a = bakeProbe(scene, one, 7, p);
  const ProbeResult b = bakeProbe(scene, two, 7, p);
  CHECK(a.energy == b.energy);
  CHECK(sameBits(pack(a), pack(b)));
  // Another probe index is another random stream: the responses differ.
  CHECK(bakeProbe(scene, one, 8, p).energy != a.energy);
  // A baker that baked other probes first gives the same bits as a fresh one.
  ProbeBaker baker(scene, one);
  baker.bake(3, {2.f, 1.6f, 2.f});
  CHECK(sameBits(pack(baker.bake(7, p)), pack(a)));
  // pack/unpack round trip.
  CHECK(sameBits(pack(unpack(pack(a), probeShape(scene, one))), pack(a)));
}

TEST_CASE("Bake probe: direct sound and parameters are physical", "[bake]") {
  const SceneDesc scene = shoebox();
  const ProbeResult r = bakeProbe(scene, quickSettings(), 0, {5.f, 1.6f, 3.5f});
  // Source 3 m away: delay 3 / c, intensity 1 / (4 pi 9) before air absorption (< 1 % at 3 m
  // in the 1 kHz band, ISO 9613-1).
  CHECK(r.directDelay[0] == Approx(3.0 / 343.0).epsilon(1e-4));
  CHECK(r.directEnergy[4] == Approx(1.0 / (4.0 * M_PI * 9.0)).epsilon(0.01));
  CHECK(r.sti[0] > 0.0f);
  CHECK(r.sti[0] < 1.0f);
  CHECK(r.stiCi[0] >= 0.0f);
}

TEST_CASE("Bake probe: the SH energy's channel 0 adds up to the response", "[bake]") {
  const SceneDesc scene = shoebox();
  const BakeSettings settings = quickSettings();
  const ProbeShape shape = probeShape(scene, settings);
  const ProbeResult r = bakeProbe(scene, settings, 0, {5.f, 1.6f, 3.5f});
  // Per 10 ms bin and band: channel 0 (Y_0 = 1) holds the energy of the response's 10 bins
  // (the same arrivals; float rounding of ~10^4 additions: 1e-4 relative).
  for (size_t k = 0; k < shape.directionalBins(); ++k)
    for (size_t b = 0; b < kNumBands; ++b) {
      double whole = 0.0;
      for (size_t j = k * kDirectionalBinFactor;
           j < std::min(shape.bins, (k + 1) * kDirectionalBinFactor); ++j)
        whole += r.energy[j * kNumBands + b];
      CHECK(r.sh[(k * kShChannels) * kNumBands + b] == Approx(whole).epsilon(1e-4).margin(1e-12));
    }
}

// Oracle: the SN3D first-order harmonics (AmbiX, Nachbar et al. 2011) of a plane wave from
// azimuth phi, elevation theta are Y = (1, sin phi cos theta, sin theta, cos phi cos theta) in
// ACN order. In an anechoic box (absorption 1: no reflection carries energy) the only arrival
// is the direct sound, from phi = 45, theta = 30 degrees in the bake's frame (a listener at
// yaw 0: x = world +x, y (left) = world -z, z (up) = world +y): its 10 ms bin must hold
// E (1, 0.612372, 0.5, 0.612372) to float rounding (1e-5 relative).
TEST_CASE("Bake probe: a single plane wave's SH energy is its energy times Y(direction)",
          "[bake]") {
  const glm::vec3 probe{5.f, 1.5f, 3.5f};
  // Toward the source, world: (cos 30 cos 45, sin 30, -cos 30 sin 45), 2 m away.
  const glm::vec3 toSource{0.6123724f, 0.5f, -0.6123724f};
  SceneDesc scene = test::makeShoebox({10.f, 3.f, 7.f}, Bands(1.f), 0.f, probe + 2.f * toSource,
                                      probe);
  const ProbeResult r = bakeProbe(scene, quickSettings(), 0, probe);
  REQUIRE(r.directDelay[0] < 0.01f);  // 5.8 ms: directional bin 0
  const double table[4] = {1.0, 0.6123724, 0.5, 0.6123724};
  for (size_t b = 0; b < kNumBands; ++b) {
    REQUIRE(r.directEnergy[b] > 0.f);
    for (size_t c = 0; c < kShChannels; ++c)
      CHECK(r.sh[c * kNumBands + b] == Approx(table[c] * r.directEnergy[b]).epsilon(1e-5));
    // Nothing else arrives: every later bin is empty.
    for (size_t k = 1; k < probeShape(scene, quickSettings()).directionalBins(); ++k)
      CHECK(r.sh[(k * kShChannels) * kNumBands + b] == 0.f);
  }
  for (size_t c = 0; c < 3; ++c) CHECK(r.directDirection[c] == Approx(toSource[c]).epsilon(1e-5));
}

TEST_CASE("Bake file: round trip, done mask, completion", "[bake]") {
  test::TempDir dir("bake_file");
  const SceneDesc scene = shoebox();
  const BakeHeader h = headerFor(scene, quickSettings(), 2.0);
  const std::string path = (dir.path() / "b.h5").string();
  const ProbeResult r = bakeProbe(scene, h.settings, 1, h.probes.positions[1]);
  {
    BakeFile f = BakeFile::create(path, path, h);
    f.commit(1, r);
  }
  {
    BakeFile f = BakeFile::open(path, BakeFile::Access::kInspect);
    CHECK_FALSE(f.complete());
    const auto done = f.done();
    CHECK(done[0] == 0);
    CHECK(done[1] == 1);
    CHECK(f.damaged().empty());
    CHECK(f.header().hashes == h.hashes);
    CHECK(f.header().probes.positions.size() == h.probes.positions.size());
    const auto energy = f.readAll("energy");
    const size_t n = h.shape.energyFloats();
    CHECK(std::equal(r.energy.begin(), r.energy.end(), energy.begin() + std::ptrdiff_t(n)));
  }
  {
    BakeFile f = BakeFile::open(path, BakeFile::Access::kWrite);
    // Probe 0 is not stored: the file is not marked complete, and says which probe.
    try {
      f.markComplete();
      FAIL("marked complete with probe 0 missing");
    } catch (const InputError& e) {
      CHECK(std::string(e.what()).find("probe 0 is not stored") != std::string::npos);
    }
  }
  CHECK_FALSE(BakeFile::open(path, BakeFile::Access::kRead).complete());
  {
    BakeFile f = BakeFile::open(path, BakeFile::Access::kWrite);
    for (size_t p = 0; p < h.probes.positions.size(); ++p)
      if (p != 1) f.commit(p, bakeProbe(scene, h.settings, p, h.probes.positions[p]));
    f.markComplete();
  }
  CHECK(BakeFile::open(path, BakeFile::Access::kRead).complete());
}

TEST_CASE("Bake file: truncated, foreign or missing files are refused naming the file",
          "[bake]") {
  test::TempDir dir("bake_bad");
  const SceneDesc scene = shoebox();
  const std::string path = (dir.path() / "b.h5").string();
  { BakeFile::create(path, path, headerFor(scene, quickSettings(), 2.0)); }
  const auto size = std::filesystem::file_size(path);
  const std::string cut = (dir.path() / "cut.h5").string();
  std::filesystem::copy_file(path, cut);
  std::filesystem::resize_file(cut, size / 2);
  for (const std::string& bad : {cut, (dir.path() / "none.h5").string()}) {
    try {
      BakeFile::open(bad, BakeFile::Access::kRead);
      FAIL("no error");
    } catch (const InputError& e) {
      CHECK(e.file() == bad);
    }
  }
  const std::string text = (dir.path() / "text.h5").string();
  std::ofstream(text) << "not hdf5\n";
  CHECK_THROWS_AS(BakeFile::open(text, BakeFile::Access::kRead), InputError);
}

TEST_CASE("Bake probe: exact early paths are stored and counted in the response", "[bake]") {
  SceneDesc scene = shoebox();
  scene.propagation.exactOrder = 3;
  const glm::vec3 probe(5.f, 1.6f, 3.5f);
  const ProbeResult r = bakeProbe(scene, quickSettings(), 0, probe);
  REQUIRE(r.earlyCount[0] >= 6);  // at least the 6 first-order image sources of the box
  CHECK(r.earlyFound[0] >= r.earlyCount[0]);
  // The floor's image source (2, -1.6, 3.5): 4.386 m, and the ceiling's (2, 4.4, 3.5): 4.104 m.
  const double c = scene.propagation.speedOfSound;
  for (const double length : {std::sqrt(9.0 + 3.2 * 3.2), std::sqrt(9.0 + 2.8 * 2.8)}) {
    bool found = false;
    for (size_t j = 0; j < size_t(r.earlyCount[0]); ++j)
      found |= std::abs(r.early[j * kEarlyPathFloats] - length / c) < 1e-6;
    CHECK(found);
  }
  // Shortest first.
  for (size_t j = 1; j < size_t(r.earlyCount[0]); ++j)
    CHECK(r.early[j * kEarlyPathFloats] >= r.early[(j - 1) * kEarlyPathFloats]);
  // With the exact paths added back, the response carries what the estimators alone carry at
  // exact_order 0: broadband G within the two bakes' 95 % confidence half-widths.
  scene.propagation.exactOrder = 0;
  const ProbeResult plain = bakeProbe(scene, quickSettings(), 0, probe);
  CHECK(plain.earlyCount[0] == 0);
  const size_t g = size_t(8 * kParameters + 6);
  CHECK(std::abs(r.parameters[g] - plain.parameters[g]) <=
        r.parametersCi[g] + plain.parametersCi[g]);
}

TEST_CASE("Bake grid: probes on or near a moving object in its first pose are skipped", "[bake]") {
  // Oracle: geometry: a door leaf standing open as a moving object, a 2 x 2 m sheet in the
  // plane x = 5.1 (z 2.1..4.1, floor to 2 m) in its pose at t = 0, where the bake's traces
  // have it. A 1 m grid at 1.6 m has its cell centres at x = 0.5, 1.5, ...: those at x = 4.5
  // and 5.5 lie 0.6 and 0.4 m from the leaf's plane; with a 0.5 m radius the ones at 5.5 whose
  // z lies beside the leaf (2.5, 3.5) are within it and skipped, those at 4.5 kept.
  SceneDesc scene = shoebox();
  const ProbeGrid without = makeProbeGrid(scene, GridRequest{1.0, 1.6, 0.5f}, "d.json");
  ObjectDesc leaf;
  leaf.name = "leaf";
  test::addPanel(leaf.mesh, {0.f, 0.f, 0.f}, {0.f, 2.f, 0.f}, {0.f, 0.f, 2.f}, 0);
  ObjectKeyframe open;
  open.position = {5.1f, 0.f, 2.1f};
  leaf.trajectory = {open};
  scene.objects.push_back(leaf);
  const ProbeGrid with = makeProbeGrid(scene, GridRequest{1.0, 1.6, 0.5f}, "d.json");
  CHECK(with.nearSurface == without.nearSurface + 2);
  for (const glm::vec3& p : with.positions)
    CHECK_FALSE((p.x == 5.5f && (p.z == 2.5f || p.z == 3.5f)));
  CHECK(with.positions.size() + 2 == without.positions.size());
  // A probe in the leaf's own plane, on it, which no ray from the probe meets but edge-on.
  const ProbeGrid on =
      placeProbes(scene, {{5.1f, 1.6f, 3.f}, {2.5f, 1.6f, 3.f}}, 0.5f, "d.json", "--probes");
  CHECK(on.nearSurface == 1);
  REQUIRE(on.positions.size() == 1);
  CHECK(on.positions[0].x == 2.5f);
}
