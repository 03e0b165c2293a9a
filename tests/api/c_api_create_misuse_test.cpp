// The C API's creation calls misused as a careless host would: dpc_engine_create_from_data
// with broken pointers, counts, indices and coordinates, dpc_engine_create_from_file with bad
// paths and options, each in a forked child (tests/api/misuse.h).
#include <sys/resource.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cfloat>
#include <climits>
#include <cmath>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "dpc/dpc.h"
#include "tests/api/misuse.h"

using namespace dpc::test;

namespace {

using B = BoxData;
using D = dpc_scene_data;

/// A case's call: createBox with `edit`.
std::function<int()> create(std::function<void(B&, D&)> edit) {
  return [edit] { return createBox(edit); };
}

/// dpc_engine_create_from_data with broken pointers, counts and indices.
std::vector<Misuse> dataCases() {
  return {
      {"box", DPC_OK, create([](B&, D&) {}), ""},
      {"NULL data", kBad,
       [] {
         dpc_engine* e = nullptr;
         return dpc_engine_create_from_data(nullptr, nullptr, &e);
       },
       "data is NULL"},
      {"NULL out", kBad,
       [] {
         BoxData b;
         return dpc_engine_create_from_data(&b.data(), nullptr, nullptr);
       },
       "out is NULL"},
      {"struct_size 0", DPC_ERR_VERSION, create([](B&, D& d) { d.struct_size = 0; }),
       "struct_size"},
      {"vertices NULL", kBad, create([](B&, D& d) { d.mesh.vertices = nullptr; }),
       "mesh.vertices: NULL with vertex_count 8"},
      {"indices NULL", kBad, create([](B&, D& d) { d.mesh.indices = nullptr; }),
       "mesh.indices: NULL with triangle_count 12"},
      {"materials NULL", kBad, create([](B&, D& d) { d.mesh.materials = nullptr; }),
       "mesh.materials: NULL with triangle_count 12"},
      {"index == vertex_count", kInput, create([](B& b, D& d) {
         b.indices[5] = 8;
         d.mesh.indices = b.indices.data();
       }),
       "mesh.indices[5]"},
      {"index UINT32_MAX", kInput, create([](B& b, D& d) {
         b.indices[0] = UINT32_MAX;
         d.mesh.indices = b.indices.data();
       }),
       "mesh.indices[0]"},
      {"triangle_count past the indices' end", kInput,
       create([](B&, D& d) { d.mesh.vertex_count = 7; }), "mesh.indices"},
      {"material index == material_count", kInput, create([](B& b, D& d) {
         b.materials[3] = 1;
         d.mesh.materials = b.materials.data();
       }),
       "mesh.materials[3]"},
      {"material_count 0", kInput, create([](B&, D& d) { d.material_count = 0; }), "material"},
      {"material_count -1", kInput, create([](B&, D& d) { d.material_count = -1; }), "material"},
      {"materials pointer NULL", kBad, create([](B&, D& d) { d.materials = nullptr; }),
       "materials: NULL with material_count 1"},
      {"source_count 0", kInput, create([](B&, D& d) { d.source_count = 0; }), "sources"},
      {"source_count -1", kInput, create([](B&, D& d) { d.source_count = -1; }), "sources"},
      {"source_count INT_MAX", kInput, create([](B&, D& d) { d.source_count = INT_MAX; }),
       "sources"},
      {"sources NULL", kBad, create([](B&, D& d) { d.sources = nullptr; }),
       "sources: NULL with source_count 1"},
      {"signal sample 1e38", kInput, create([](B& b, D& d) {
         static const float loud[2] = {0.5f, 1e38f};
         b.sources[0].signal = loud;
         b.sources[0].signal_frames = 2;
         d.sources = b.sources.data();
       }),
       "sources[0].signal: sample 1 is 1e+38, beyond +-1e+06"},
      {"source_count 257", kInput, create([](B& b, D& d) {
         b.sources.resize(257, b.sources.front());
         d.sources = b.sources.data();
         d.source_count = 257;
       }),
       "sources: 257"},
      {"signal NULL with frames", kBad, create([](B& b, D& d) {
         b.sources[0].signal_frames = 100;
         d.sources = b.sources.data();
       }),
       "sources[0].signal: NULL with signal_frames 100"},
  };
}

/// dpc_engine_create_from_data with values beyond the scene's limits.
std::vector<Misuse> dataValueCases() {
  return {
      {"vertex 1e20", kInput, create([](B& b, D& d) {
         b.vertices[4] = 1e20f;
         d.mesh.vertices = b.vertices.data();
       }),
       "1e+20 is outside"},
      {"vertex FLT_MAX", kInput, create([](B& b, D& d) {
         b.vertices[0] = FLT_MAX;
         d.mesh.vertices = b.vertices.data();
       }),
       "is outside"},
      {"vertex nan", kInput, create([](B& b, D& d) {
         b.vertices[2] = kNan;
         d.mesh.vertices = b.vertices.data();
       }),
       "nan is outside"},
      {"listener 1e30", kInput, create([](B&, D& d) { d.listener_position[1] = 1e30f; }),
       "listener_position"},
      {"listener radius -1", kInput, create([](B&, D& d) { d.listener_radius = -1; }),
       "listener_radius"},
      {"sample rate 8000", kInput, create([](B&, D& d) { d.sample_rate = 8000; }),
       "sample_rate: 8000 is outside [16000, 192000] Hz"},
      {"rays INT_MAX", kInput, create([](B&, D& d) { d.rays_per_frame = INT_MAX; }),
       "rays_per_frame"},
      {"cache_tau 3e38", kInput, create([](B&, D& d) { d.cache_tau = 3e38f; }), "cache_tau"},
      {"additional listeners 64", kInput, create([](B& b, D& d) {
         b.listeners.assign(64, dpc_listener{{4, 1.5f, 2}, 0.5f, 0, 0, 0});
         d.additional_listeners = b.listeners.data();
         d.additional_listener_count = 64;
       }),
       "listeners"},
      {"additional listeners -1", kInput,
       create([](B&, D& d) { d.additional_listener_count = -1; }), "additional_listener_count"},
      {"additional listeners NULL with count 1", kBad,
       create([](B&, D& d) { d.additional_listener_count = 1; }),
       "additional_listeners: NULL with additional_listener_count 1"},
      {"output 99", kInput, create([](B&, D& d) { d.output = dpc_output_format(99); }), "output"},
  };
}

/// Values with no upper bound in a caller's mind: spheres, patches, names.
std::vector<Misuse> sizeAndNameCases() {
  return {
      // A sphere of infinite or astronomic radius encloses the room and hears nothing: refused
      // (the limit is (0, 10^6] m), never rendered as silence.
      {"listener radius inf", kInput, create([](B&, D& d) { d.listener_radius = kInf; }),
       "listener_radius: inf is outside (0, 1000000] m"},
      {"listener radius FLT_MAX", kInput, create([](B&, D& d) { d.listener_radius = FLT_MAX; }),
       "listener_radius: "},
      {"listener radius 1e30", kInput, create([](B&, D& d) { d.listener_radius = 1e30f; }),
       "listener_radius: 1e+30 is outside (0, 1000000] m"},
      {"listener radius 10^6", DPC_OK, create([](B&, D& d) { d.listener_radius = 1e6f; }), ""},
      {"patch size inf", kInput, create([](B&, D& d) { d.patch_size = kInf; }),
       "patch_size: inf must be > 0 m"},
      {"material name with a terminal escape", kInput, create([](B& b, D&) {
         b.material.name = "\x1b[2Jwalls";
       }),
       "must not contain control characters"},
  };
}

/// dpc_engine_create_from_file with bad paths and options.
std::vector<Misuse> optionCases() {
  auto with = [](std::function<void(dpc_engine_options&)> edit) {
    return [edit] { return createWithOptions(edit); };
  };
  return {
      {"NULL path", kBad,
       [] {
         dpc_engine* e = nullptr;
         return dpc_engine_create_from_file(nullptr, nullptr, &e);
       },
       "scene_path is NULL"},
      {"empty path", kInput,
       [] {
         dpc_engine* e = nullptr;
         return dpc_engine_create_from_file("", nullptr, &e);
       },
       ""},
      {"a folder", kInput,
       [] {
         dpc_engine* e = nullptr;
         return dpc_engine_create_from_file(DPC_SOURCE_DIR "/scenes", nullptr, &e);
       },
       "scenes"},
      {"/dev/zero", kInput,
       [] {
         dpc_engine* e = nullptr;
         return dpc_engine_create_from_file("/dev/zero", nullptr, &e);
       },
       "/dev/zero"},
      {"options struct_size 0", DPC_ERR_VERSION, with([](auto& o) { o.struct_size = 0; }),
       "dpc_engine_options.struct_size"},
      {"sample rate 15999", kBad, with([](auto& o) { o.sample_rate = 15999; }), "sample_rate"},
      {"sample rate 192001", kBad, with([](auto& o) { o.sample_rate = 192001; }), "sample_rate"},
      {"sample rate -1", kBad, with([](auto& o) { o.sample_rate = -1; }), "sample_rate"},
      {"block 15", kBad, with([](auto& o) { o.block_size = 15; }), "block_size"},
      {"block 8193", kBad, with([](auto& o) { o.block_size = 8193; }), "block_size"},
      {"rays INT_MAX", kBad, with([](auto& o) { o.rays_per_frame = INT_MAX; }), "rays_per_frame"},
      {"rays -1", kBad, with([](auto& o) { o.rays_per_frame = -1; }), "rays_per_frame"},
      {"output 99", kBad, with([](auto& o) { o.output = dpc_output_format(99); }), "output"},
      {"output -1", kBad, with([](auto& o) { o.output = dpc_output_format(-1); }), "output"},
      {"sample rate 16000", DPC_OK, with([](auto& o) { o.sample_rate = 16000; }), ""},
  };
}

/// The shoebox scene with `cacheMb` MiB of path cache per source-listener pair and a pool of
/// `poolMb` MiB for all pairs, written to a
/// file of its own (removed before returning), created with host inputs only in a process
/// whose address space is capped at 8 GB (so that the memory available is the same on any
/// machine: half of it, 4 GB).
int createWithCache(double cacheMb, double poolMb) {
#ifndef __SANITIZE_ADDRESS__
  // AddressSanitizer reserves terabytes of shadow address space, so under it the process keeps
  // the machine's memory (16 GB is still beyond half of any machine this runs on).
  const rlimit limit{8ull << 30, 8ull << 30};
  setrlimit(RLIMIT_AS, &limit);
#endif
  std::ifstream in(DPC_SOURCE_DIR "/scenes/shoebox.json");
  std::stringstream text;
  text << in.rdbuf();
  std::string json = text.str();
  const std::string scenes = DPC_SOURCE_DIR "/scenes/";
  json.replace(json.find("\"shoebox.obj\""), 13, "\"" + scenes + "shoebox.obj\"");
  json.replace(json.find("\"signals/"), 9, "\"" + scenes + "signals/");
  json.replace(json.find("\"propagation\": {"), 16,
               "\"propagation\": { \"cache_memory_mb\": " + std::to_string(cacheMb) +
                   ", \"cache_pool_mb\": " + std::to_string(poolMb) + ",");
  char path[] = "/tmp/dpc_cache_scene_XXXXXX";
  const int fd = mkstemp(path);
  if (fd < 0 || write(fd, json.data(), json.size()) != ssize_t(json.size())) return kNoEngine;
  close(fd);
  dpc_engine_options o;
  dpc_engine_options_init(&o);
  o.host_inputs_only = 1;
  dpc_engine* e = nullptr;
  const dpc_status status = dpc_engine_create_from_file(path, &o, &e);
  dpc_engine_destroy(e);
  unlink(path);
  return status;
}

/// Work and memory beyond reach: refused before anything is allocated, naming the setting.
std::vector<Misuse> workloadCases() {
  return {
      {"cache 16384 MiB per pair, pool 65536 MiB", kInput,
       [] { return createWithCache(16384, 65536); }, "propagation.cache_memory_mb: "},
      {"cache 16384 MiB per pair, default pool", DPC_OK, [] { return createWithCache(16384, 256); },
       ""},
      {"cache 64 MiB per pair", DPC_OK, [] { return createWithCache(64, 256); }, ""},
  };
}

}  // namespace

TEST_CASE("C API misuse: work and memory beyond reach", "[misuse]") {
  runAll(workloadCases());
}

TEST_CASE("C API misuse: scene data", "[misuse]") {
  runAll(dataCases());
  runAll(dataValueCases());
  runAll(sizeAndNameCases());
}

TEST_CASE("C API misuse: scene files and options", "[misuse]") {
  runAll(optionCases());
}
