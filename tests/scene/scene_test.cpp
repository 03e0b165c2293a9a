// Scene loading: the shipped scenes, defaults, every key, and the errors of bad JSON and OBJ
// files (each names the file and the field).
#include "scene/scene.h"

#include <catch2/catch.hpp>
#include <glm/common.hpp>
#include <string>

#include "common/input_error.h"
#include "scene/trajectory.h"
#include "tests/scene/scene_fixture.h"

using namespace dpc;
using namespace dpc::test;
using Catch::Matchers::Contains;

TEST_CASE("Shipped shoebox scene loads", "[scene]") {
  const SceneDesc s = loadScene(kSourceDir + "/scenes/shoebox.json");
  CHECK(s.mesh.triangles.size() == 12);
  CHECK(s.mesh.materialIndex.size() == s.mesh.triangles.size());
  REQUIRE(s.materials.size() == 3);  // sorted by name
  CHECK(s.materials[0].name == "ceiling");
  CHECK(s.materials[1].name == "floor");
  CHECK(s.materials[2].name == "walls");
  for (uint32_t m : s.mesh.materialIndex) CHECK(m < s.materials.size());
  REQUIRE(s.sources.size() == 1);
  CHECK(fs::exists(s.sources[0].signalPath));
  CHECK(s.listeners[0].loop);
  CHECK(s.listeners[0].trajectory.size() == 5);
  CHECK(s.propagation.raysPerFrame == 4096);
  CHECK(s.propagation.maxOrder == 200);
  CHECK(s.propagation.frameRate == 15.f);
  CHECK(s.propagation.estimator == Estimator::kDpc);
  CHECK(s.propagation.speedOfSound == Approx(343.2).epsilon(1e-3));
  CHECK(s.warnings.empty());
  // Box bounds: 10 x 3 x 7 m.
  glm::vec3 lo(1e9f), hi(-1e9f);
  for (const auto& v : s.mesh.vertices) lo = glm::min(lo, v), hi = glm::max(hi, v);
  CHECK(hi.x - lo.x == 10.f);
  CHECK(hi.y - lo.y == 3.f);
  CHECK(hi.z - lo.z == 7.f);
  // The listener path keeps the sphere inside the room, >= 0.5 m from every wall.
  for (double t = 0.0; t < 12.0; t += 0.1) {
    const glm::vec3 p = listenerPositionAt(s.listeners[0], t);
    const float clearance = s.listeners[0].radius + 0.5f;
    CHECK(p.x >= clearance);
    CHECK(p.x <= 10.f - clearance);
    CHECK(p.z >= clearance);
    CHECK(p.z <= 7.f - clearance);
  }
}

TEST_CASE("Shipped hall scene loads", "[scene]") {
  const SceneDesc s = loadScene(kSourceDir + "/scenes/hall.json");
  CHECK(s.mesh.triangles.size() >= 10000);
  CHECK(s.mesh.materialIndex.size() == s.mesh.triangles.size());
  CHECK(s.materials.size() >= 6);
  std::vector<int> uses(s.materials.size(), 0);
  for (uint32_t m : s.mesh.materialIndex) {
    REQUIRE(m < s.materials.size());
    ++uses[m];
  }
  for (size_t i = 0; i < s.materials.size(); ++i) {
    INFO(s.materials[i].name);
    CHECK(uses[i] > 0);
    CHECK(s.materials[i].absorption.min() >= 0.f);
    CHECK(s.materials[i].absorption.max() <= 1.f);
    CHECK(s.materials[i].scattering.min() >= 0.f);
    CHECK(s.materials[i].scattering.max() <= 1.f);
  }
  REQUIRE(s.sources.size() == 2);
  for (const auto& src : s.sources) CHECK(fs::exists(src.signalPath));
  CHECK(s.listeners[0].trajectory.back().timeSeconds == Approx(20.0));
  CHECK(s.warnings.empty());
}

TEST_CASE("Minimal scene loads with defaults", "[scene]") {
  Fixture f;
  const SceneDesc s = f.load();
  CHECK(s.mesh.triangles.size() == 12);
  CHECK(s.materials[1].name == "walls");
  CHECK(s.materials[1].absorption == Bands(0.1f));
  CHECK(s.materials[1].scattering == Bands(0.2f));  // a number means all bands
  CHECK(s.materials[0].absorption == Bands(0.3f));  // a number means all bands
  CHECK(s.materials[0].scattering == Bands(0.5f));  // default
  CHECK(s.mesh.materialIndex[0] == 0);              // floor
  CHECK(s.mesh.materialIndex[2] == 1);              // walls
  CHECK(s.sources[0].gainDb == 0.f);
  CHECK(s.listeners[0].radius == 0.1f);
  CHECK_FALSE(s.listeners[0].loop);
  const PropagationSettings defaults;
  CHECK(s.propagation.raysPerFrame == defaults.raysPerFrame);
  CHECK(s.propagation.cacheTau == defaults.cacheTau);
  CHECK(s.propagation.dpcWeighting == defaults.dpcWeighting);
  CHECK(s.audio.sampleRate == 48000);
  CHECK(fs::path(s.meshPath).filename() == "cube.obj");
  CHECK(s.warnings.empty());
}

TEST_CASE("Scattering per octave band is read in band order", "[scene]") {
  Fixture f;
  f.scene["materials"]["walls"]["scattering"] = {0.05, 0.05, 0.1, 0.2, 0.3, 0.5, 0.7, 0.9};
  const SceneDesc s = f.load();
  Bands expected;
  const float values[kNumBands] = {0.05f, 0.05f, 0.1f, 0.2f, 0.3f, 0.5f, 0.7f, 0.9f};
  for (int b = 0; b < kNumBands; ++b) expected[b] = values[b];
  CHECK(s.materials[1].scattering == expected);
}

TEST_CASE("Propagation and audio keys are read", "[scene]") {
  Fixture f;
  f.scene["propagation"] = json::parse(R"({
    "rays_per_frame": 1000, "max_order": 7, "patch_size": 0.25, "cache_tau": 0,
    "frame_rate": 30, "ir_length": 1.5, "seed": 18446744073709551615,
    "estimator": "path_tracing", "dpc_weighting": "seed", "temperature": 0,
    "humidity": 80, "air_absorption": false, "reflection_scattering": false })");
  f.scene["audio"] = json::parse(R"({ "sample_rate": 44100, "block_size": 256 })");
  const SceneDesc s = f.load();
  CHECK(s.propagation.raysPerFrame == 1000);
  CHECK(s.propagation.maxOrder == 7);
  CHECK(s.propagation.patchSize == 0.25f);
  CHECK(s.propagation.cacheTau == 0.f);
  CHECK(s.propagation.frameRate == 30.f);
  CHECK(s.propagation.irLength == 1.5f);
  CHECK(s.propagation.seed == 18446744073709551615ull);
  CHECK(s.propagation.estimator == Estimator::kPathTracing);
  CHECK(s.propagation.dpcWeighting == DpcWeighting::kSeed);
  CHECK(s.propagation.speedOfSound == Approx(331.3));  // from temperature 0 degC
  CHECK(s.propagation.humidityPercent == 80.f);
  CHECK_FALSE(s.propagation.airAbsorption);
  CHECK_FALSE(s.propagation.reflectionScattering);
  CHECK(s.audio.sampleRate == 44100);
  CHECK(s.audio.blockSize == 256);

  f.scene["propagation"]["speed_of_sound"] = 340;
  CHECK(f.load().propagation.speedOfSound == 340.f);
}

TEST_CASE("reflection_scattering asked for with diffraction off is a warning, not ignored",
          "[scene]") {
  Fixture f;
  f.scene["propagation"] = {{"diffraction", false}};
  CHECK(f.load().warnings.empty());  // the default on is not the user's word
  f.scene["propagation"]["reflection_scattering"] = true;
  const SceneDesc s = f.load();
  REQUIRE(s.warnings.size() == 1);
  CHECK_THAT(s.warnings[0], Contains("scene.json: propagation.reflection_scattering: has no "
                                     "effect with propagation.diffraction false"));
  f.scene["propagation"]["diffraction"] = true;
  CHECK(f.load().warnings.empty());
}

TEST_CASE("Comment keys are ignored, unknown keys are refused", "[scene]") {
  Fixture f;
  f.scene["_comment"] = "anything";
  f.scene["listener"]["_note"] = 42;
  CHECK_NOTHROW(f.load());

  f.scene["propagation"] = {{"rays_per_fram", 10}};
  const std::string e = f.error();
  CHECK_THAT(e, Contains("scene.json: propagation.rays_per_fram: unknown key"));
  CHECK_THAT(e, Contains("did you mean \"rays_per_frame\""));

  Fixture g;
  g.scene["listner"] = json::object();
  CHECK_THAT(g.error(), Contains("scene.json: listner: unknown key"));
}

TEST_CASE("Missing or malformed scene file", "[scene][errors]") {
  Fixture f;
  try {
    loadScene(f.path("nope.json"));
    FAIL("expected an InputError");
  } catch (const InputError& e) {
    CHECK_THAT(e.what(), Contains("nope.json") && Contains("not found"));
  }
  f.write("bad.json", "{\n  \"mesh\": \"cube.obj\",\n  \"materials\" {}\n}\n");
  try {
    loadScene(f.path("bad.json"));
    FAIL("expected an InputError");
  } catch (const InputError& e) {
    CHECK_THAT(e.what(), Contains("bad.json: malformed JSON at line 3, column 15"));
  }
  f.write("overflow.json", "{\n  \"mesh\": 1e999\n}\n");
  try {
    loadScene(f.path("overflow.json"));
    FAIL("expected an InputError");
  } catch (const InputError& e) {
    CHECK_THAT(e.what(), Contains("overflow.json: malformed JSON at line 2, column 11"));
  }
  f.write("array.json", "[1, 2]");
  try {
    loadScene(f.path("array.json"));
    FAIL("expected an InputError");
  } catch (const InputError& e) {
    CHECK_THAT(e.what(), Contains("array.json: expected a JSON object"));
  }
}

TEST_CASE("Missing required keys", "[scene][errors]") {
  SECTION("sources") {
    Fixture f;
    f.scene.erase("sources");
    CHECK_THAT(f.error(), Contains("scene.json: sources: missing required key"));
  }
  SECTION("mesh") {
    Fixture f;
    f.scene.erase("mesh");
    CHECK_THAT(f.error(), Contains("scene.json: mesh: missing required key"));
  }
  SECTION("absorption") {
    Fixture f;
    f.scene["materials"]["walls"].erase("absorption");
    CHECK_THAT(f.error(), Contains("scene.json: materials.walls.absorption: missing required key"));
  }
  SECTION("source position") {
    Fixture f;
    f.scene["sources"][0].erase("position");
    CHECK_THAT(f.error(), Contains("scene.json: sources[0].position: missing required key"));
  }
  SECTION("listener position without trajectory") {
    Fixture f;
    f.scene["listener"].erase("position");
    CHECK_THAT(f.error(), Contains("scene.json: listener.position: missing required key"));
  }
}

TEST_CASE("Wrong types and values", "[scene][errors]") {
  SECTION("radius as a string") {
    Fixture f;
    f.scene["listener"]["radius"] = "big";
    CHECK_THAT(f.error(), Contains("scene.json: listener.radius: expected a number, got string"));
  }
  SECTION("position of 2 numbers") {
    Fixture f;
    f.scene["sources"][0]["position"] = {1, 2};
    CHECK_THAT(f.error(), Contains("scene.json: sources[0].position: expected an array of 3"));
  }
  SECTION("position element as bool") {
    Fixture f;
    f.scene["sources"][0]["position"] = {1, true, 2};
    CHECK_THAT(f.error(), Contains("scene.json: sources[0].position[1]: expected a number"));
  }
  SECTION("loop as a number") {
    Fixture f;
    f.scene["listener"]["loop"] = 1;
    CHECK_THAT(f.error(), Contains("scene.json: listener.loop: expected true or false"));
  }
  SECTION("sources as an object") {
    Fixture f;
    f.scene["sources"] = json::object();
    CHECK_THAT(f.error(), Contains("scene.json: sources: expected an array"));
  }
  SECTION("no sources") {
    Fixture f;
    f.scene["sources"] = json::array();
    CHECK_THAT(f.error(), Contains("scene.json: sources: at least one source"));
  }
  SECTION("rays_per_frame not an integer") {
    Fixture f;
    f.scene["propagation"]["rays_per_frame"] = 10.5;
    CHECK_THAT(f.error(),
               Contains("scene.json: propagation.rays_per_frame: 10.5 is not an integer"));
  }
  SECTION("negative seed") {
    Fixture f;
    f.scene["propagation"]["seed"] = -1;
    CHECK_THAT(f.error(), Contains("scene.json: propagation.seed: expected an unsigned integer"));
  }
  SECTION("unknown estimator") {
    Fixture f;
    f.scene["propagation"]["estimator"] = "magic";
    CHECK_THAT(f.error(), Contains("scene.json: propagation.estimator: \"magic\" is not one of"));
  }
  SECTION("unknown dpc_weighting") {
    Fixture f;
    f.scene["propagation"]["dpc_weighting"] = "EMA";
    CHECK_THAT(f.error(), Contains("scene.json: propagation.dpc_weighting: \"EMA\""));
  }
  SECTION("sample rate out of range") {
    Fixture f;
    f.scene["audio"]["sample_rate"] = 1000;
    CHECK_THAT(f.error(),
               Contains("scene.json: audio.sample_rate: 1000 is outside [16000, 192000]"));
  }
  SECTION("duplicate source names") {
    Fixture f;
    f.scene["sources"].push_back(f.scene["sources"][0]);
    CHECK_THAT(f.error(), Contains("scene.json: sources[1].name: duplicate source name"));
  }
}

TEST_CASE("Material values are checked", "[scene][errors]") {
  SECTION("absorption outside [0, 1]") {
    Fixture f;
    f.scene["materials"]["walls"]["absorption"][3] = 1.7;
    CHECK_THAT(f.error(),
               Contains("scene.json: materials.walls.absorption[3]: 1.7 is outside [0, 1]"));
  }
  SECTION("negative broadband absorption") {
    Fixture f;
    f.scene["materials"]["floor"]["absorption"] = -0.1;
    CHECK_THAT(f.error(),
               Contains("scene.json: materials.floor.absorption: -0.1 is outside [0, 1]"));
  }
  SECTION("absorption array of the wrong length") {
    Fixture f;
    f.scene["materials"]["walls"]["absorption"] = {0.1, 0.1, 0.1, 0.1, 0.1, 0.1};
    CHECK_THAT(f.error(), Contains("scene.json: materials.walls.absorption: expected 8 values") &&
                              Contains("got 6"));
  }
  SECTION("scattering outside [0, 1]") {
    Fixture f;
    f.scene["materials"]["walls"]["scattering"] = 1.5;
    CHECK_THAT(f.error(),
               Contains("scene.json: materials.walls.scattering: 1.5 is outside [0, 1]"));
  }
  SECTION("scattering per band: an element outside [0, 1]") {
    Fixture f;
    f.scene["materials"]["walls"]["scattering"] = {0.1, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, -0.2};
    CHECK_THAT(f.error(),
               Contains("scene.json: materials.walls.scattering[7]: -0.2 is outside [0, 1]"));
  }
  SECTION("scattering array of the wrong length") {
    Fixture f;
    f.scene["materials"]["walls"]["scattering"] = {0.1, 0.2, 0.3};
    CHECK_THAT(f.error(), Contains("scene.json: materials.walls.scattering: expected 8 values") &&
                              Contains("got 3"));
  }
  SECTION("scattering of the wrong type") {
    Fixture f;
    f.scene["materials"]["walls"]["scattering"] = "high";
    CHECK_THAT(f.error(), Contains("scene.json: materials.walls.scattering: expected a number or "
                                   "an array of 8 numbers in [0, 1]"));
  }
  SECTION("material typo") {
    Fixture f;
    f.scene["materials"]["walls"]["scatering"] = 0.5;
    CHECK_THAT(f.error(), Contains("scene.json: materials.walls.scatering: unknown key") &&
                              Contains("did you mean \"scattering\""));
  }
}

TEST_CASE("Listener, propagation and signal values are checked", "[scene][errors]") {
  auto expect = [](auto mutate, const std::string& expected) {
    Fixture f;
    mutate(f.scene);
    CHECK_THAT(f.error(), Contains(expected));
  };
  expect([](json& s) { s["listener"]["radius"] = 0; },
         "scene.json: listener.radius: 0 is outside (0, 1000000] m");
  expect([](json& s) { s["listener"]["radius"] = -0.5; },
         "scene.json: listener.radius: -0.5 is outside (0, 1000000] m");
  expect([](json& s) { s["propagation"]["rays_per_frame"] = 0; },
         "scene.json: propagation.rays_per_frame: 0 is outside [1,");
  expect([](json& s) { s["propagation"]["frame_rate"] = 0; },
         "scene.json: propagation.frame_rate: 0 is outside [1, 120] Hz");
  expect([](json& s) { s["propagation"]["ir_length"] = -1; },
         "scene.json: propagation.ir_length: -1 is outside (0, 60] s");
  expect([](json& s) { s["propagation"]["patch_size"] = 0; },
         "scene.json: propagation.patch_size: 0 must be > 0");
  expect([](json& s) { s["propagation"]["cache_tau"] = -0.5; },
         "scene.json: propagation.cache_tau: -0.5 is outside [0, 3600] s");
  expect([](json& s) { s["propagation"]["humidity"] = 120; },
         "scene.json: propagation.humidity: 120 is outside [0, 100]");
  expect(
      [](json& s) {
        s["listener"]["trajectory"] = json::parse(
            R"([{"t": 0, "position": [0.2, 0.5, 0.5]}, {"t": 2, "position": [0.8, 0.5, 0.5]},
                {"t": 2, "position": [0.5, 0.5, 0.5]}])");
      },
      "scene.json: listener.trajectory[2].t: 2 is not greater than the previous keyframe's t");
  expect(
      [](json& s) {
        s["listener"]["trajectory"] = json::parse(R"([{"position": [0.2, 0.5, 0.5]}])");
      },
      "scene.json: listener.trajectory[0].t: missing required key");
  expect([](json& s) { s["sources"][0]["signal"] = "missing.wav"; },
         "scene.json: sources[0].signal: file");
  expect([](json& s) { s["mesh"] = "missing.obj"; }, "scene.json: mesh: mesh file");
}

TEST_CASE("OBJ problems name the OBJ file", "[scene][errors]") {
  SECTION("NaN vertex") {
    Fixture f;
    f.write("cube.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nusemtl walls\nf 1 2 3\n");
    CHECK_THAT(f.error(), Contains("cube.obj: vertex 2 (line 2): coordinate nan is not finite"));
  }
  SECTION("infinite vertex") {
    Fixture f;
    f.write("cube.obj", "v 0 0 0\nv 1 0 0\n# comment\nv 0 1e999 0\nusemtl walls\nf 1 2 3\n");
    CHECK_THAT(f.error(), Contains("cube.obj: vertex 3 (line 4): coordinate 1e999 is not finite"));
  }
  SECTION("garbage vertex") {
    Fixture f;
    f.write("cube.obj", "v 0 0 0\nv 1 zero 0\nv 0 1 0\nusemtl walls\nf 1 2 3\n");
    CHECK_THAT(f.error(), Contains("cube.obj: vertex 2 (line 2): \"zero\" is not a number"));
  }
  SECTION("garbage after a vertex's coordinates") {
    Fixture f;
    f.write("cube.obj", "v 0 0 0\nv 10 3 7 abc\nv 0 1 0\nusemtl walls\nf 1 2 3\n");
    CHECK_THAT(f.error(), Contains("cube.obj: vertex 2 (line 2): \"abc\" is not a number"));
    f.write("cube.obj", "v 0 0 0\nv 1 0 7abc\nv 0 1 0\nusemtl walls\nf 1 2 3\n");
    CHECK_THAT(f.error(), Contains("cube.obj: vertex 2 (line 2): \"7abc\" is not a number"));
  }
  SECTION("a weight or a vertex colour after the coordinates loads") {
    Fixture f;
    f.write("cube.obj", "v 0 0 0 1\nv 1 0 0 0.5 0.2 0.1\nv 0 1 0\nusemtl walls\nf 1 2 3\n");
    const SceneDesc scene = f.load();
    REQUIRE(scene.mesh.vertices.size() == 3);
    CHECK(scene.mesh.vertices[1].x == 1.f);
  }
  SECTION("a comment after a vertex, and CRLF line ends, load") {
    Fixture f;
    f.write("cube.obj",
            "v 0 0 0 # origin\r\nv 1 0 0#x\r\nv 0 1 0 1\t# weight\r\nusemtl walls\r\nf 1 2 3\r\n");
    const SceneDesc scene = f.load();
    REQUIRE(scene.mesh.vertices.size() == 3);
    CHECK(scene.mesh.vertices[1].x == 1.f);
    CHECK(scene.mesh.vertices[2].y == 1.f);
  }
  SECTION("a comment in place of a coordinate is refused") {
    Fixture f;
    f.write("cube.obj", "v 0 0 # z\nv 1 0 0\nv 0 1 0\nusemtl walls\nf 1 2 3\n");
    CHECK_THAT(f.error(), Contains("expected 3 coordinates x y z"));
  }
  SECTION("empty mesh") {
    Fixture f;
    f.write("cube.obj", "# nothing but vertices\nv 0 0 0\nv 1 0 0\n");
    CHECK_THAT(f.error(), Contains("cube.obj: mesh is empty"));
  }
  SECTION("all triangles degenerate") {
    Fixture f;
    f.write("cube.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nusemtl walls\nf 1 2 3\nf 1 1 2\n");
    CHECK_THAT(f.error(), Contains("cube.obj: all 2 triangles are degenerate"));
  }
  SECTION("unknown material") {
    Fixture f;
    f.write("cube.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl marble\nf 1 2 3\n");
    CHECK_THAT(f.error(), Contains("cube.obj: usemtl marble: material \"marble\" is not defined"));
  }
  SECTION("no usemtl and no default material") {
    Fixture f;
    f.write("cube.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    CHECK_THAT(f.error(), Contains("cube.obj: face 1: face has no usemtl"));
  }
  SECTION("vertex index out of range") {
    Fixture f;
    f.write("cube.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl walls\nf 1 2 3\nf 1 2 9\n");
    CHECK_THAT(f.error(), Contains("cube.obj: face 2: vertex index 9 is out of range"));
  }
}

TEST_CASE("OBJ: a copy of a triangle (same corners, same winding) is dropped with a warning",
          "[scene]") {
  Fixture f;
  // Triangle 1; its copy through other vertices at the same positions, rotated; its other side
  // (a zero-thickness wall's second face, kept); a third copy.
  f.write("cube.obj",
          "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 0 0\nv 0 1 0\nusemtl walls\n"
          "f 1 2 3\nf 5 1 4\nf 3 2 1\nf 2 3 1\n");
  const SceneDesc s = f.load();
  REQUIRE(s.mesh.triangles.size() == 2);
  CHECK(s.mesh.triangles[0] == std::array<uint32_t, 3>{0, 1, 2});
  CHECK(s.mesh.triangles[1] == std::array<uint32_t, 3>{2, 1, 0});
  bool duplicateWarning = false;
  for (const auto& w : s.warnings)
    duplicateWarning |= w.find("cube.obj: 2 duplicate") != std::string::npos &&
                        w.find("the first from face 2") != std::string::npos;
  CHECK(duplicateWarning);
}

TEST_CASE("OBJ details: default material, polygons, relative indices, degenerate warning",
          "[scene]") {
  Fixture f;
  f.scene["materials"]["default"] = {{"absorption", 0.5}};
  f.write("cube.obj",
          "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
          "f 1 2 3 4\n"      // quad, no usemtl -> default, fan-triangulated
          "usemtl walls \n"  // trailing space is trimmed
          "f -2 -3 -4\n"     // relative indices = 3 2 1 (the fan's first triangle, other side)
          "f 1 2 2\n");      // degenerate: dropped with a warning
  const SceneDesc s = f.load();
  REQUIRE(s.mesh.triangles.size() == 3);
  CHECK(s.materials[s.mesh.materialIndex[0]].name == "default");
  CHECK(s.materials[s.mesh.materialIndex[1]].name == "default");
  CHECK(s.materials[s.mesh.materialIndex[2]].name == "walls");
  CHECK(s.mesh.triangles[1] == std::array<uint32_t, 3>{0, 2, 3});
  CHECK(s.mesh.triangles[2] == std::array<uint32_t, 3>{2, 1, 0});
  bool degenerateWarning = false, unusedWarning = false;
  for (const auto& w : s.warnings) {
    degenerateWarning |= w.find("cube.obj: 1 degenerate") != std::string::npos;
    unusedWarning |= w.find("materials.floor: not used") != std::string::npos;
  }
  CHECK(degenerateWarning);
  CHECK(unusedWarning);
}

TEST_CASE("The path cache pool is sized by the scene unless given", "[scene]") {
  Fixture f;
  CHECK(f.load().propagation.cachePoolMb == kCachePoolAuto);  // the default
  f.scene["propagation"]["cache_pool_mb"] = "auto";
  CHECK(f.load().propagation.cachePoolMb == kCachePoolAuto);
  f.scene["propagation"]["cache_pool_mb"] = 96;
  CHECK(f.load().propagation.cachePoolMb == 96.f);
  f.scene["propagation"]["cache_pool_mb"] = "large";
  CHECK_THAT(f.error(), Catch::Contains("propagation.cache_pool_mb") &&
                            Catch::Contains("\"auto\""));
  f.scene["propagation"]["cache_pool_mb"] = -1;  // the sentinel is no value a file can give
  CHECK_THAT(f.error(), Catch::Contains("propagation.cache_pool_mb"));
}

TEST_CASE("Shipped dense hall: 64 talkers inside one 20 x 15 x 4 m room", "[scene]") {
  const SceneDesc s = loadScene(kSourceDir + "/scenes/dense_hall.json");
  glm::vec3 lo(1e9f), hi(-1e9f);
  for (const auto& v : s.mesh.vertices) lo = glm::min(lo, v), hi = glm::max(hi, v);
  CHECK(hi - lo == glm::vec3(20.f, 4.f, 15.f));
  REQUIRE(s.sources.size() == 64);
  for (const SourceDesc& src : s.sources) {
    INFO(src.name);
    CHECK(glm::all(glm::greaterThan(src.position, lo)));
    CHECK(glm::all(glm::lessThan(src.position, hi)));
    CHECK(src.trajectory.empty());  // static: the many-source benchmark's case
    // The walking listener's sphere never reaches a talker.
    for (double t = 0.0; t < 30.0; t += 0.1)
      CHECK(glm::distance(listenerPositionAt(s.listeners[0], t), src.position) >
            s.listeners[0].radius);
  }
  CHECK(s.propagation.cachePoolMb == kCachePoolAuto);
  CHECK(s.warnings.empty());
}
