// The C API's bake calls (include/dpc/dpc.h, "Baked playback"): a bake made by dpc-bake opens
// for an engine of its scene and attaches while the engine is stopped; a bake of another scene,
// of another response length (a 2 s bake for a scene of 1 s), a truncated or damaged file and
// NULL arguments give codes and a message naming the file and the field.
#include <catch2/catch.hpp>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "dpc/dpc.h"

namespace {

const std::string kBakeProgram = DPC_BINARY_DIR "/apps/dpc-bake";

/// A quick bake of scenes/shoebox.json (2 m grid, few rays) made with dpc-bake at `path`.
void makeBake(const std::string& path) {
  const std::string cmd = kBakeProgram + " " DPC_SOURCE_DIR "/scenes/shoebox.json --out " + path +
                          " --spacing 2 --rays 200 --frames 4 --threads 1 > /dev/null 2>&1";
  REQUIRE(std::system(cmd.c_str()) == 0);
}

/// scenes/shoebox.json with another ir_length, written to `path` (its mesh and signal named by
/// absolute paths).
void writeShoeboxWithIrLength(const std::string& path, const std::string& irLength) {
  std::ifstream in(DPC_SOURCE_DIR "/scenes/shoebox.json");
  std::stringstream text;
  text << in.rdbuf();
  std::string s = text.str();
  const auto replace = [&s](const std::string& from, const std::string& to) {
    const size_t at = s.find(from);
    REQUIRE(at != std::string::npos);
    s.replace(at, from.size(), to);
  };
  replace("\"ir_length\": 2.0", "\"ir_length\": " + irLength);
  replace("\"shoebox.obj\"", "\"" DPC_SOURCE_DIR "/scenes/shoebox.obj\"");
  replace("\"signals/speech.wav\"", "\"" DPC_SOURCE_DIR "/scenes/signals/speech.wav\"");
  std::ofstream(path) << s;
}

dpc_engine* engineFor(const char* scene) {
  dpc_engine_options o;
  dpc_engine_options_init(&o);
  o.host_inputs_only = 1;
  o.rays_per_frame = 200;
  dpc_engine* e = nullptr;
  REQUIRE(dpc_engine_create_from_file(scene, &o, &e) == DPC_OK);
  return e;
}

}  // namespace

TEST_CASE("C API bake: open and attach and play - another scene or a truncated file or NULL refused") {
  dpc_engine* e = engineFor(DPC_SOURCE_DIR "/scenes/shoebox.json");
  dpc_bake* bake = reinterpret_cast<dpc_bake*>(1);
  CHECK(dpc_bake_open(e, nullptr, &bake) == DPC_ERR_INVALID_ARGUMENT);
  CHECK(bake == nullptr);
  CHECK(dpc_bake_open(nullptr, "x.h5", &bake) == DPC_ERR_INVALID_ARGUMENT);
  CHECK(dpc_engine_attach_bake(nullptr, nullptr) == DPC_ERR_INVALID_ARGUMENT);
  CHECK(dpc_bake_probe_count(nullptr) == -1);
  dpc_bake_destroy(nullptr);
  if (!std::filesystem::exists(kBakeProgram)) {
    // Built without HDF5: the calls exist and say so.
    CHECK(dpc_bake_open(e, "x.h5", &bake) == DPC_ERR_UNSUPPORTED);
    dpc_engine_destroy(e);
    return;
  }
  const auto dir = std::filesystem::temp_directory_path() / "dpc_c_api_bake";
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "shoebox.h5").string();
  makeBake(path);
  REQUIRE(dpc_bake_open(e, path.c_str(), &bake) == DPC_OK);
  CHECK(dpc_bake_probe_count(bake) > 0);
  CHECK(dpc_engine_attach_bake(e, bake) == DPC_OK);
  dpc_bake_destroy(bake);  // the engine keeps its own reference
  CHECK(dpc_engine_step(e) == DPC_OK);
  CHECK(dpc_engine_step(e) == DPC_OK);
  // The scene's one source stands at its baked position, its listener among the probes.
  dpc_stats stats{};
  stats.struct_size = sizeof stats;
  REQUIRE(dpc_engine_get_stats(e, &stats) == DPC_OK);
  CHECK(stats.baked_responses == 2);
  CHECK(stats.bake_fallbacks == 0);
  // Running: no attaching.
  REQUIRE(dpc_engine_start(e) == DPC_OK);
  CHECK(dpc_engine_attach_bake(e, nullptr) == DPC_ERR_STATE);
  CHECK(dpc_engine_stop(e) == DPC_OK);
  CHECK(dpc_engine_attach_bake(e, nullptr) == DPC_OK);
  // Another scene: its geometry's hash named with the file; and the open bake refused by its
  // engine.
  dpc_engine* other = engineFor(DPC_SOURCE_DIR "/scenes/two_rooms.json");
  CHECK(dpc_bake_open(other, path.c_str(), &bake) == DPC_ERR_INPUT);
  CHECK(bake == nullptr);
  const std::string msg = dpc_last_error();
  CHECK(msg.find(path + ": hash_geometry:") == 0);
  CHECK(msg.find('\n') == std::string::npos);
  REQUIRE(dpc_bake_open(e, path.c_str(), &bake) == DPC_OK);
  CHECK(dpc_engine_attach_bake(other, bake) == DPC_ERR_INVALID_ARGUMENT);
  dpc_bake_destroy(bake);
  // Truncated: refused naming the file.
  const std::string cut = (dir / "cut.h5").string();
  std::filesystem::copy_file(path, cut, std::filesystem::copy_options::overwrite_existing);
  std::filesystem::resize_file(cut, std::filesystem::file_size(path) / 2);
  CHECK(dpc_bake_open(e, cut.c_str(), &bake) == DPC_ERR_INPUT);
  CHECK(std::string(dpc_last_error()).find(cut) == 0);
  // A byte of the stored responses flipped (the middle of the file is the energy dataset):
  // refused naming the file, one line.
  const std::string flipped = (dir / "flipped.h5").string();
  std::filesystem::copy_file(path, flipped, std::filesystem::copy_options::overwrite_existing);
  {
    std::fstream f(flipped, std::ios::in | std::ios::out | std::ios::binary);
    const auto middle = std::streamoff(std::filesystem::file_size(flipped) / 2);
    f.seekg(middle);
    const char c = char(f.get() ^ 0x10);
    f.seekp(middle);
    f.put(c);
  }
  CHECK(dpc_bake_open(e, flipped.c_str(), &bake) == DPC_ERR_INPUT);
  CHECK(std::string(dpc_last_error()).find(flipped + ": ") == 0);
  CHECK(std::string(dpc_last_error()).find('\n') == std::string::npos);
  // The same scene with 1 s responses: the 2 s bake is refused, naming ir_length_s.
  const std::string oneSecond = (dir / "shoebox_1s.json").string();
  writeShoeboxWithIrLength(oneSecond, "1.0");
  dpc_engine* shorter = engineFor(oneSecond.c_str());
  CHECK(dpc_bake_open(shorter, path.c_str(), &bake) == DPC_ERR_INPUT);
  CHECK(std::string(dpc_last_error()).find(path + ": ir_length_s:") == 0);
  REQUIRE(dpc_bake_open(e, path.c_str(), &bake) == DPC_OK);
  CHECK(dpc_engine_attach_bake(shorter, bake) == DPC_ERR_INVALID_ARGUMENT);
  dpc_bake_destroy(bake);
  dpc_engine_destroy(shorter);
  dpc_engine_destroy(other);
  dpc_engine_destroy(e);
  std::filesystem::remove_all(dir);
}
