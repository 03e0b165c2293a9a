// dpc-demo end to end: bit-identical renders for a seed, and every bad-input case giving a
// one-line error naming the file and the field, a non-zero exit status and no output file.
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <sstream>
#include <string>

#include "runtime/offline_renderer.h"
#include "scene/scene.h"
#include "testing/test_scenes.h"

using namespace dpc;
namespace fs = std::filesystem;

namespace {

const std::string kDemo = std::string(DPC_BINARY_DIR) + "/apps/dpc-demo";
const std::string kScenes = std::string(DPC_SOURCE_DIR) + "/scenes";

struct Run {
  int status = -1;
  std::string err;
};

Run run(const std::string& args) {
  // One file per process: ctest -j runs this binary's test cases side by side.
  const fs::path errFile =
      fs::temp_directory_path() / ("dpc_demo_test_stderr_" + std::to_string(::getpid()) + ".txt");
  const std::string cmd = kDemo + " " + args + " --quiet >/dev/null 2>" + errFile.string();
  const int raw = std::system(cmd.c_str());
  Run r;
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  std::ifstream in(errFile);
  std::stringstream ss;
  ss << in.rdbuf();
  r.err = ss.str();
  fs::remove(errFile);
  return r;
}

/// A scratch folder with a valid small scene (copy of the shoebox's mesh and signal) that a
/// test then breaks in one place.
struct Fixture {
  fs::path dir;
  Fixture() {
    dir = fs::temp_directory_path() / ("dpc_demo_test_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    fs::copy_file(kScenes + "/shoebox.obj", dir / "room.obj", fs::copy_options::overwrite_existing);
    fs::copy_file(kScenes + "/signals/speech.wav", dir / "speech.wav",
                  fs::copy_options::overwrite_existing);
  }
  ~Fixture() { fs::remove_all(dir); }
  std::string writeScene(const std::string& json) const {
    static int counter = 0;
    const fs::path p = dir / ("scene" + std::to_string(++counter) + ".json");
    std::ofstream(p) << json;
    return p.string();
  }
  std::string sceneJson(const std::string& materials, const std::string& listener,
                        const std::string& signal = "speech.wav") const {
    return R"({ "mesh": "room.obj", "materials": )" + materials +
           R"(, "sources": [ { "name": "talker", "position": [2, 1.5, 2], "signal": ")" + signal +
           R"(" } ], "listener": )" + listener +
           R"(, "propagation": { "rays_per_frame": 200, "max_order": 10, "ir_length": 0.3 } })";
  }
};

std::string materialsFor(const fs::path& obj, const std::string& absorption) {
  // Every usemtl name in the OBJ gets the given absorption.
  std::ifstream in(obj);
  std::string line, json = "{";
  std::set<std::string> names;
  while (std::getline(in, line))
    if (line.rfind("usemtl ", 0) == 0) names.insert(line.substr(7));
  bool first = true;
  for (const std::string& n : names) {
    json += (first ? "" : ", ") + std::string("\"") + n + "\": { \"absorption\": " + absorption +
            ", \"scattering\": 0.5 }";
    first = false;
  }
  return json + "}";
}

/// An offline render of the shoebox scene with its dry signals and the given propagation
/// (rays per frame, maximum order, IR length s) and duration (s); the members may be changed
/// between renders.
struct ShoeboxRender {
  SceneDesc scene = loadScene(kScenes + "/shoebox.json");
  PropagationSettings ps = scene.propagation;
  DrySignals dry = loadDrySignals(scene);
  OfflineOptions opt;

  ShoeboxRender(int rays, int maxOrder, float irLength, double durationSeconds) {
    ps.raysPerFrame = rays;
    ps.maxOrder = maxOrder;
    ps.irLength = irLength;
    opt.durationSeconds = durationSeconds;
  }
  OfflineResult render() const {
    return renderOffline(test::shared(scene), ps, test::shared(dry), opt);
  }
};

/// A fresh folder under the system's temporary one (prefix + process id) holding the shipped
/// shoebox's mesh and dry signals, for scene variants written beside them.
fs::path shoeboxFolder(const std::string& prefix) {
  const fs::path dir = fs::temp_directory_path() / (prefix + std::to_string(::getpid()));
  fs::create_directories(dir);
  fs::copy(kScenes + "/shoebox.obj", dir / "shoebox.obj");
  fs::copy(kScenes + "/signals", dir / "signals", fs::copy_options::recursive);
  return dir;
}

/// The shipped shoebox scene's JSON text.
std::string shoeboxSceneText() {
  std::ifstream in(kScenes + "/shoebox.json");
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

/// Whether two files hold the same bytes (cmp -s).
bool sameFiles(const fs::path& a, const fs::path& b) {
  return std::system(("cmp -s " + a.string() + " " + b.string()).c_str()) == 0;
}

}  // namespace

TEST_CASE("Offline render is bit-identical for a seed and differs for another", "[offline]") {
  ShoeboxRender shoebox(300, 20, 0.5f, 1.0);
  const OfflineResult a = shoebox.render();
  const OfflineResult b = shoebox.render();
  shoebox.ps.seed += 1;
  const OfflineResult c = shoebox.render();
  REQUIRE(a.listeners[0].output.frames() == size_t(shoebox.scene.audio.sampleRate));
  CHECK(a.listeners[0].output.channels == b.listeners[0].output.channels);
  CHECK(a.listeners[0].output.channels != c.listeners[0].output.channels);
  // 15 frames per second for 1 s: every frame's IR reached the convolver.
  CHECK(a.totals.frames == 15);
  CHECK(a.listeners[0].irsApplied == 15);
  double energy = 0;
  for (float x : a.listeners[0].output.channels[0]) {
    REQUIRE(std::isfinite(x));
    energy += double(x) * x;
  }
  CHECK(energy > 0.0);
}

TEST_CASE("Same-seed dpc-demo renders write byte-identical files", "[offline]") {
  // The files, not the buffers: nothing the writers add (headers, chunks, timestamps) may vary.
  const fs::path dir = fs::temp_directory_path() / ("dpc_demo_bytes_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  auto render = [&](const std::string& name, int seed) {
    const std::string out = (dir / name).string();
    const Run r = run(kScenes + "/shoebox.json --offline " + out + ".wav --ir-out " + out +
                      "-ir.wav --er-out " + out + ".csv --duration 0.4 --rays 256 --max-order 10" +
                      " --seed " + std::to_string(seed));
    INFO(r.err);
    REQUIRE(r.status == 0);
  };
  auto same = [&](const std::string& a, const std::string& b) {
    const std::string cmd = "cmp -s " + (dir / a).string() + " " + (dir / b).string();
    return std::system(cmd.c_str()) == 0;
  };
  render("a", 7);
  render("b", 7);
  render("c", 8);
  CHECK(same("a.wav", "b.wav"));
  CHECK(same("a-ir.wav", "b-ir.wav"));
  CHECK(same("a.csv", "b.csv"));
  CHECK_FALSE(same("a.wav", "c.wav"));  // the seed matters: the comparison is not vacuous
  fs::remove_all(dir);
}

TEST_CASE("dpc-demo --seed takes every seed a scene file takes, and no other", "[offline]") {
  // The scene's "seed" and dpc_scene_data.seed are unsigned 64-bit: so is the flag.
  const fs::path dir = fs::temp_directory_path() / ("dpc_demo_seed_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string base =
      kScenes + "/shoebox.json --offline " + (dir / "o.wav").string() + " --duration 0.1 --rays 16";
  for (const char* seed : {"0", "9223372036854775808", "18446744073709551615"}) {
    const Run r = run(base + " --seed " + seed);
    INFO(seed << ": " << r.err);
    CHECK(r.status == 0);
  }
  fs::remove_all(dir);
  for (const char* seed : {"-1", "18446744073709551616", "1.5"}) {
    const Run r = run(base + " --seed " + seed);
    INFO(seed << ": " << r.err);
    CHECK(r.status == 1);
    CHECK(r.err.find("--seed: '" + std::string(seed) + "' is not a whole number in [0, 2^64)") !=
          std::string::npos);
  }
}

TEST_CASE("dpc-demo --block-size sets the offline renderer's block as audio.block_size does",
          "[offline]") {
  // The engine block changes an offline render (IR swaps fall on block boundaries), so the
  // flag is applied there too, not only in live runs.
  const fs::path dir = shoeboxFolder("dpc_demo_block_");
  std::string scene = shoeboxSceneText();
  const std::string key = "\"block_size\": 512";
  REQUIRE(scene.find(key) != std::string::npos);
  std::ofstream((dir / "shoebox.json").string()) << scene;
  std::ofstream((dir / "b256.json").string())
      << scene.replace(scene.find(key), key.size(), "\"block_size\": 256");
  auto render = [&](const std::string& sceneFile, const std::string& out,
                    const std::string& extra) {
    const Run r = run((dir / sceneFile).string() + " --offline " + (dir / out).string() +
                      " --duration 0.5 --rays 256" + extra);
    INFO(r.err);
    REQUIRE(r.status == 0);
  };
  render("shoebox.json", "default.wav", "");
  render("shoebox.json", "flag.wav", " --block-size 256");
  render("b256.json", "key.wav", "");
  auto same = [&](const std::string& a, const std::string& b) {
    return sameFiles(dir / a, dir / b);
  };
  CHECK(same("flag.wav", "key.wav"));
  CHECK_FALSE(same("flag.wav", "default.wav"));  // the block matters: not a vacuous comparison
  fs::remove_all(dir);
}

TEST_CASE("dpc-demo --hrtf keeps a scene's ambisonic_binaural output", "[offline]") {
  // --hrtf alone turns a scene's mono or stereo output binaural; an output that already
  // decodes through the HRTF stays as it is (it became plain binaural without a word).
  const fs::path dir = shoeboxFolder("dpc_demo_hrtf_");
  std::string scene = shoeboxSceneText();
  const std::string key = "\"audio\": {";
  REQUIRE(scene.find(key) != std::string::npos);
  std::ofstream((dir / "ab.json").string())
      << scene.replace(scene.find(key), key.size(), key + " \"output\": \"ambisonic_binaural\",");
  const std::string sofa = "/usr/share/libmysofa/default.sofa";  // the scene's default HRTF
  auto render = [&](const std::string& out, const std::string& extra) {
    const Run r = run((dir / "ab.json").string() + " --offline " + (dir / out).string() +
                      " --duration 0.3 --rays 256" + extra);
    INFO(r.err);
    REQUIRE(r.status == 0);
  };
  render("scene.wav", "");
  render("flag.wav", " --hrtf " + sofa);
  render("binaural.wav", " --output binaural --hrtf " + sofa);
  auto same = [&](const std::string& a, const std::string& b) {
    return sameFiles(dir / a, dir / b);
  };
  CHECK(same("flag.wav", "scene.wav"));
  CHECK_FALSE(same("binaural.wav", "scene.wav"));  // the outputs differ: not a vacuous check
  fs::remove_all(dir);
}

TEST_CASE("Offline render streamed block by block equals the held render", "[offline]") {
  ShoeboxRender shoebox(200, 10, 0.3f, 0.51);  // not a whole number of blocks: the last is cut
  const SceneDesc& scene = shoebox.scene;
  const OfflineResult held = shoebox.render();
  std::vector<float> streamed;
  size_t calls = 0;
  shoebox.opt.sink = [&](size_t listener, const float* const* planar, size_t frames) {
    CHECK(listener == 0);
    CHECK(frames <= size_t(scene.audio.blockSize));
    streamed.insert(streamed.end(), planar[0], planar[0] + frames);
    ++calls;
  };
  const OfflineResult r = shoebox.render();
  const audio::AudioData& heldOut = held.listeners.at(0).output;
  CHECK(r.listeners.at(0).output.channels.empty());
  CHECK(calls == (heldOut.frames() + scene.audio.blockSize - 1) / scene.audio.blockSize);
  CHECK(streamed == heldOut.channels[0]);
}

TEST_CASE("dpc-demo refuses bad input with one line naming file and field", "[errors]") {
  Fixture fx;
  const std::string good = materialsFor(fx.dir / "room.obj", "0.2");
  const std::string listener = R"({ "position": [7, 1.6, 5], "radius": 0.5 })";
  const fs::path out = fx.dir / "out.wav";
  struct Case {
    const char* name;
    std::string sceneArg;     // path passed to dpc-demo
    std::string mustMention;  // field or file the message must name
  };
  auto scene = [&](const std::string& json) { return fx.writeScene(json); };
  const std::string malformed = scene("{ \"mesh\": ");
  const Case cases[] = {
      {"missing scene file", (fx.dir / "nope.json").string(), "nope.json"},
      {"malformed JSON", malformed, fs::path(malformed).filename().string()},
      {"wrong type", scene(fx.sceneJson(good, R"({ "position": [7, 1.6, 5], "radius": "big" })")),
       "listener.radius"},
      {"absorption outside [0, 1]",
       scene(fx.sceneJson(materialsFor(fx.dir / "room.obj", "1.7"), listener)), "absorption"},
      {"radius <= 0", scene(fx.sceneJson(good, R"({ "position": [7, 1.6, 5], "radius": 0 })")),
       "listener.radius"},
      {"unknown material",
       scene(fx.sceneJson(R"({ "only_this": { "absorption": 0.1 } })", listener)), "room.obj"},
      {"unreadable WAV", scene(fx.sceneJson(good, listener, "scene.json")), "sources[0].signal"},
      {"missing WAV", scene(fx.sceneJson(good, listener, "nothing.wav")), "sources[0].signal"},
  };
  for (const Case& c : cases) {
    fs::remove(out);
    const Run r = run(c.sceneArg + " --offline " + out.string());
    INFO(c.name << ": status " << r.status << ", stderr: " << r.err);
    CHECK(r.status != 0);
    CHECK(r.err.find(c.mustMention) != std::string::npos);
    CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);  // one line
    CHECK_FALSE(fs::exists(out));
  }

  // Mesh problems: a NaN vertex, an empty mesh, a mesh of only degenerate triangles.
  const std::pair<const char*, std::string> meshes[] = {
      {"NaN coordinate", "v 0 0 0\nv 1 0 0\nv nan 1 0\nusemtl m\nf 1 2 3\n"},
      {"empty mesh", "# nothing\n"},
      {"degenerate mesh", "v 0 0 0\nv 1 0 0\nv 2 0 0\nusemtl m\nf 1 2 3\n"},
  };
  for (const auto& [name, obj] : meshes) {
    std::ofstream(fx.dir / "room.obj") << obj;
    const std::string s = scene(fx.sceneJson(R"({ "m": { "absorption": 0.1 } })", listener));
    fs::remove(out);
    const Run r = run(s + " --offline " + out.string());
    INFO(name << ": status " << r.status << ", stderr: " << r.err);
    CHECK(r.status != 0);
    CHECK(r.err.find("room.obj") != std::string::npos);
    CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
    CHECK_FALSE(fs::exists(out));
  }

  // Bad flags.
  fs::copy_file(kScenes + "/shoebox.obj", fx.dir / "room.obj",
                fs::copy_options::overwrite_existing);
  const std::string s = scene(fx.sceneJson(good, listener));
  for (const char* flag :
       {"--rays 0", "--tau -1", "--estimator magic", "--max-order -2", "--listener nobody"}) {
    const Run r = run(s + " --offline " + out.string() + " " + flag);
    INFO(flag << ": " << r.err);
    CHECK(r.status != 0);
    CHECK(r.err.find(std::string(flag).substr(0, std::string(flag).find(' '))) !=
          std::string::npos);
    CHECK_FALSE(fs::exists(out));
  }
  // And the same scene renders when nothing is wrong.
  const Run ok = run(s + " --offline " + out.string() + " --duration 0.5");
  INFO(ok.err);
  CHECK(ok.status == 0);
  CHECK(fs::exists(out));
}

TEST_CASE("Two-room scene: every listener rendered to OUT-NAME.wav, or one with --listener",
          "[offline][dynamic]") {
  const fs::path dir = fs::temp_directory_path() / ("dpc_demo_two_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string base = " --duration 0.3 --rays 256 --max-order 10 ";
  const Run all = run(kScenes + "/two_rooms.json --offline " + (dir / "out.wav").string() + base);
  INFO(all.err);
  CHECK(all.status == 0);
  CHECK(fs::exists(dir / "out-a.wav"));
  CHECK(fs::exists(dir / "out-b.wav"));
  CHECK_FALSE(fs::exists(dir / "out.wav"));
  const Run one = run(kScenes + "/two_rooms.json --offline " + (dir / "one.wav").string() + base +
                      "--listener b");
  CHECK(one.status == 0);
  CHECK(fs::exists(dir / "one.wav"));
  CHECK_FALSE(fs::exists(dir / "one-b.wav"));
  fs::remove_all(dir);
}

TEST_CASE("dpc-demo says how many ways round edges its diffraction left out", "[offline]") {
  // What a user reads at the end of a render. Behind scenes/louvre.json's 50 slats, with the
  // line of sight on a slat, the way round them needs chains round more edges than a chain
  // holds (engine/edge_chain.h): the direct sound's diffraction leaves them out, and the summary
  // must say so rather than stay silent; in the shoebox nothing is in the way and it says 0.
  const fs::path dir =
      fs::temp_directory_path() / ("dpc_demo_chains_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path behind = dir / "behind_slat.json";  // the line of sight crosses z = -0.165 m
  std::ofstream(behind) << R"({"mesh": ")" << kScenes << R"(/louvre.obj",
    "materials": {"ground": {"absorption": 0.1, "scattering": 0.5},
                  "wood": {"absorption": 0.1, "scattering": 0.2}},
    "sources": [{"name": "talker", "position": [-3.0, 1.2, 0.0],
                 "signal": ")"
                        << kScenes << R"(/signals/speech.wav"}],
    "listener": {"position": [3.0, 1.2, -0.33], "radius": 0.1}})";
  auto leftOut = [&](const std::string& scene) {
    const std::string cmd = kDemo + " " + scene + " --offline " + (dir / "out.wav").string() +
                            " --duration 0.1 --seed 1 --threads 1 2>/dev/null";
    FILE* pipe = ::popen(cmd.c_str(), "r");
    REQUIRE(pipe != nullptr);
    std::string text;
    char buffer[4096];
    for (size_t n; (n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0;) text.append(buffer, n);
    REQUIRE(::pclose(pipe) == 0);
    const std::string key = "diffraction chains left out ";
    const size_t at = text.find(key);
    INFO(text);
    REQUIRE(at != std::string::npos);
    return std::stoll(text.substr(at + key.size()));
  };
  CHECK(leftOut(behind.string()) > 0);
  CHECK(leftOut(kScenes + "/shoebox.json") == 0);
  fs::remove_all(dir);
}
