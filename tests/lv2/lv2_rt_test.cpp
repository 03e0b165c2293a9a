// The LV2 plugin's audio-thread contract, with a minimal host in the test: run() (with control
// changes, a patch:Set choosing another scene, loaded in the background, and its swap) makes no
// heap call (tests/rt/alloc_counter.h), the output stays finite and not silent, and the chosen
// scene survives save/restore into a fresh instance (read back through patch:Get on the notify
// port). Scenes load on the plugin's own thread: instantiate returns before a heavy scene is
// built, the plugin is silent until then and says when it is ready, a scene that fails to load
// is reported, and no thread of the plugin or of dpc is left after cleanup.
#include <dlfcn.h>
#include <lv2/atom/forge.h>
#include <lv2/atom/util.h>
#include <lv2/buf-size/buf-size.h>
#include <lv2/core/lv2.h>
#include <lv2/log/log.h>
#include <lv2/options/options.h>
#include <lv2/patch/patch.h>
#include <lv2/state/state.h>
#include <lv2/urid/urid.h>
#include <lv2/worker/worker.h>

#include <array>
#include <catch2/catch.hpp>
#include <cfloat>
#include <chrono>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "testing/temp_dir.h"
#include "testing/thread_count.h"
#include "tests/lv2/log_capture.h"
#include "tests/rt/alloc_counter.h"

namespace {

constexpr const char* kBundle = DPC_BINARY_DIR "/lv2/dpc.lv2/";
constexpr const char* kSceneParam = "urn:dpc:lv2:room#scene";
constexpr uint32_t kFrames = 256;

struct Host {
  std::map<std::string, LV2_URID> ids;
  std::vector<std::string> names{""};
  LV2_URID_Map map{this, [](LV2_URID_Map_Handle h, const char* uri) -> LV2_URID {
                     auto* host = static_cast<Host*>(h);
                     auto [it, fresh] = host->ids.emplace(uri, LV2_URID(host->names.size()));
                     if (fresh) host->names.push_back(uri);
                     return it->second;
                   }};
  // Worker: messages are queued by run() (copied into preallocated storage, no allocation)
  // and executed later on the test's control thread.
  std::vector<char> pending = std::vector<char>(8192);
  uint32_t pendingSize = 0;
  int scheduled = 0;
  LV2_Worker_Schedule schedule{this,
                               [](LV2_Worker_Schedule_Handle h, uint32_t size, const void* data) {
                                 auto* host = static_cast<Host*>(h);
                                 if (size > host->pending.size() || host->pendingSize)
                                   return LV2_WORKER_ERR_NO_SPACE;
                                 std::memcpy(host->pending.data(), data, size);
                                 host->pendingSize = size;
                                 ++host->scheduled;
                                 return LV2_WORKER_SUCCESS;
                               }};
  std::vector<char> response = std::vector<char>(64);
  uint32_t responseSize = 0;
  LV2_Feature mapFeature{LV2_URID__map, &map};
  LV2_Feature workerFeature{LV2_WORKER__schedule, &schedule};
  const LV2_Feature* features[3] = {&mapFeature, &workerFeature, nullptr};
  /// The map, the worker and `extra`.
  std::array<const LV2_Feature*, 4> with(const LV2_Feature* extra) {
    return {&mapFeature, &workerFeature, extra, nullptr};
  }
};

struct Instance {
  const LV2_Descriptor* d;
  LV2_Handle h;
  float in[kFrames], left[kFrames], right[kFrames];
  float controls[7] = {7.f, 1.6f, 3.5f, 180.f, 3.f, 1.6f, 3.5f};
  float latency = 0.f;
  alignas(8) uint8_t control[4096], notify[4096];
  Instance(const LV2_Descriptor* desc, Host& host, const LV2_Feature* const* features = nullptr,
           const char* bundle = kBundle)
      : d(desc) {
    h = d->instantiate(d, 48000.0, bundle, features ? features : host.features);
    REQUIRE(h);
    d->connect_port(h, 0, in);
    d->connect_port(h, 1, left);
    d->connect_port(h, 2, right);
    for (uint32_t i = 0; i < 7; ++i) d->connect_port(h, 3 + i, &controls[i]);
    d->connect_port(h, 10, control);
    d->connect_port(h, 11, notify);
    d->connect_port(h, 12, &latency);
  }
  ~Instance() { d->cleanup(h); }
  // An empty input sequence and an output sequence of full capacity, as a host prepares them.
  void clearAtoms(LV2_URID sequence) {
    auto* c = reinterpret_cast<LV2_Atom_Sequence*>(control);
    c->atom.type = sequence;
    c->atom.size = sizeof(LV2_Atom_Sequence_Body);
    c->body.unit = 0;
    c->body.pad = 0;
    auto* n = reinterpret_cast<LV2_Atom_Sequence*>(notify);
    n->atom.type = 0;
    n->atom.size = sizeof notify - sizeof(LV2_Atom);
  }
};

/// The bundle's plugin `index`: 0 the stereo "dpc room", 1 and 2 its AmbiX orders 1 and 3.
const LV2_Descriptor* loadDescriptor(uint32_t index = 0) {
  void* lib = dlopen(DPC_BINARY_DIR "/lv2/dpc.lv2/dpc_lv2.so", RTLD_NOW);
  INFO(dlerror());
  REQUIRE(lib);
  auto fn = reinterpret_cast<LV2_Descriptor_Function>(dlsym(lib, "lv2_descriptor"));
  REQUIRE(fn);
  REQUIRE(fn(3) == nullptr);
  const char* uris[] = {"urn:dpc:lv2:room", "urn:dpc:lv2:room-ambix1", "urn:dpc:lv2:room-ambix3"};
  for (uint32_t i = 0; i < 3; ++i) REQUIRE(std::string(fn(i)->URI) == uris[i]);
  return fn(index);
}

// Writes a patch message into the instance's control port (control thread).
void writePatch(Instance& x, Host& host, bool set, const std::string& path) {
  LV2_Atom_Forge forge;
  lv2_atom_forge_init(&forge, &host.map);
  lv2_atom_forge_set_buffer(&forge, x.control, sizeof x.control);
  LV2_Atom_Forge_Frame seq, obj;
  lv2_atom_forge_sequence_head(&forge, &seq, 0);
  lv2_atom_forge_frame_time(&forge, 0);
  lv2_atom_forge_object(&forge, &obj, 0,
                        host.map.map(&host, set ? LV2_PATCH__Set : LV2_PATCH__Get));
  if (set) {
    lv2_atom_forge_key(&forge, host.map.map(&host, LV2_PATCH__property));
    lv2_atom_forge_urid(&forge, host.map.map(&host, kSceneParam));
    lv2_atom_forge_key(&forge, host.map.map(&host, LV2_PATCH__value));
    lv2_atom_forge_path(&forge, path.c_str(), uint32_t(path.size()));
  }
  lv2_atom_forge_pop(&forge, &obj);
  lv2_atom_forge_pop(&forge, &seq);
}

// The scene path in a patch:Set on the notify port, or "".
std::string notifiedPath(Instance& x, Host& host) {
  const auto* seq = reinterpret_cast<const LV2_Atom_Sequence*>(x.notify);
  std::string path;
  LV2_ATOM_SEQUENCE_FOREACH(seq, ev) {
    const auto* obj = reinterpret_cast<const LV2_Atom_Object*>(&ev->body);
    const LV2_Atom* value = nullptr;
    lv2_atom_object_get(obj, host.map.map(&host, LV2_PATCH__value), &value, 0);
    if (value && value->type == host.map.map(&host, LV2_ATOM__Path))
      path.assign(static_cast<const char*>(LV2_ATOM_BODY_CONST(value)));
  }
  return path;
}

// Runs the worker's pending message on this (control) thread.
void runWorker(const LV2_Descriptor* d, LV2_Handle h, Host& host) {
  const auto* worker =
      static_cast<const LV2_Worker_Interface*>(d->extension_data(LV2_WORKER__interface));
  REQUIRE(worker);
  const uint32_t size = host.pendingSize;
  std::vector<char> msg(host.pending.begin(), host.pending.begin() + size);
  host.pendingSize = 0;
  worker->work(
      h,
      [](LV2_Worker_Respond_Handle rh, uint32_t n, const void* data) {
        auto* hst = static_cast<Host*>(rh);
        std::memcpy(hst->response.data(), data, n);
        hst->responseSize = n;
        return LV2_WORKER_SUCCESS;
      },
      &host, size, msg.data());
}

/// Runs blocks (with a dry impulse train, 10 ms of wall-clock time apart) until the plugin
/// names `path` on its notify port, which it does once the scene plays; false if it never
/// does within a minute. A message run() left for the worker before a block runs first (as a
/// host's worker would); the last block's stays pending. heapCalls (if given) counts the heap
/// calls of run().
bool runUntilPlaying(Instance& x, Host& host, const std::string& path,
                     uint64_t* heapCalls = nullptr) {
  const LV2_URID sequence = host.map.map(&host, LV2_ATOM__Sequence);
  for (int block = 0; block < 6000; ++block) {
    if (host.pendingSize) runWorker(x.d, x.h, host);
    x.clearAtoms(sequence);
    for (uint32_t i = 0; i < kFrames; ++i) x.in[i] = (block * kFrames + i) % 4800 == 0;
    {
      dpc::rt::AllocationScope scope;
      x.d->run(x.h, kFrames);
      if (heapCalls) *heapCalls += scope.counts().total();
    }
    if (notifiedPath(x, host) == path) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return false;
}

/// Runs one block whose control port holds a patch:Set of the scene `path` (silent input).
void sendPatchSet(Instance& x, Host& host, const std::string& path, uint64_t* heapCalls = nullptr) {
  x.clearAtoms(host.map.map(&host, LV2_ATOM__Sequence));
  writePatch(x, host, true, path);
  std::fill(std::begin(x.in), std::end(x.in), 0.f);
  dpc::rt::AllocationScope scope;
  x.d->run(x.h, kFrames);
  if (heapCalls) *heapCalls += scope.counts().total();
}

/// The bundle's default scene as the plugin names it.
const std::string kDefaultScenePath = std::string(kBundle) + "scene/room.json";

/// The scene path the plugin's state interface saves.
std::string savedScene(const LV2_Descriptor* d, LV2_Handle h) {
  const auto* state =
      static_cast<const LV2_State_Interface*>(d->extension_data(LV2_STATE__interface));
  REQUIRE(state);
  std::string saved;
  REQUIRE(
      state->save(
          h,
          [](LV2_State_Handle sh, uint32_t, const void* value, size_t size, uint32_t, uint32_t) {
            static_cast<std::string*>(sh)->assign(static_cast<const char*>(value), size - 1);
            return LV2_STATE_SUCCESS;
          },
          &saved, LV2_STATE_IS_POD, nullptr) == LV2_STATE_SUCCESS);
  return saved;
}

}  // namespace

TEST_CASE("LV2 plugin: run() and a scene swap make no heap call, the scene is saved") {
  const LV2_Descriptor* d = loadDescriptor();
  Host host;
  const LV2_URID sequence = host.map.map(&host, LV2_ATOM__Sequence);
  const std::string other = DPC_SOURCE_DIR "/scenes/shoebox.json";
  std::string saved;
  {
    Instance x(d, host);
    d->activate(x.h);
    uint64_t heapCalls = 0;
    REQUIRE(runUntilPlaying(x, host, kDefaultScenePath, &heapCalls));
    double energy = 0.0;
    bool finite = true;
    const auto play = [&](int block) {
      x.clearAtoms(sequence);
      for (uint32_t i = 0; i < kFrames; ++i) x.in[i] = (block * kFrames + i) % 4800 == 0;
      x.controls[0] = 7.f - 0.005f * float(block);  // the listener walks 2 m towards the source
      {
        dpc::rt::AllocationScope scope;
        d->run(x.h, kFrames);
        heapCalls += scope.counts().total();
      }
      for (uint32_t i = 0; i < kFrames; ++i) {
        finite = finite && std::isfinite(x.left[i]) && std::isfinite(x.right[i]);
        energy += double(x.left[i]) * x.left[i] + double(x.right[i]) * x.right[i];
      }
    };
    for (int block = 0; block < 100; ++block) play(block);
    sendPatchSet(x, host, other, &heapCalls);
    REQUIRE(host.scheduled == 1);
    runWorker(d, x.h, host);  // starts the load on the plugin's thread and returns
    REQUIRE(runUntilPlaying(x, host, other, &heapCalls));  // swapped in by run()
    REQUIRE(host.scheduled == 2);  // the old scene goes back to the worker to be freed
    runWorker(d, x.h, host);
    for (int block = 100; block < 400; ++block) play(block);
    CHECK(host.scheduled == 2);
    CHECK(heapCalls == 0);
    CHECK(finite);
    CHECK(energy > 1e-6);
    CHECK(x.latency == 512.f);  // one block of the scene now playing (shoebox.json: 512)
    d->deactivate(x.h);
    saved = savedScene(d, x.h);
    CHECK(saved == other);
  }
  // A fresh instance restores the saved scene (in the background), says so when it plays and
  // again on patch:Get.
  Instance y(d, host);
  const auto* state =
      static_cast<const LV2_State_Interface*>(d->extension_data(LV2_STATE__interface));
  struct Saved {
    std::string path;
    LV2_URID type;
  } s{saved, host.map.map(&host, LV2_ATOM__Path)};
  REQUIRE(state->restore(
              y.h,
              [](LV2_State_Handle sh, uint32_t, size_t* size, uint32_t* type,
                 uint32_t* flags) -> const void* {
                auto* sv = static_cast<Saved*>(sh);
                *size = sv->path.size() + 1;
                *type = sv->type;
                *flags = LV2_STATE_IS_POD;
                return sv->path.c_str();
              },
              &s, 0, nullptr) == LV2_STATE_SUCCESS);
  d->activate(y.h);
  CHECK(runUntilPlaying(y, host, other));
  y.clearAtoms(sequence);
  writePatch(y, host, false, "");
  d->run(y.h, kFrames);
  CHECK(notifiedPath(y, host) == other);
  d->deactivate(y.h);
}

TEST_CASE("LV2 plugin: the AmbiX order-3 plugin fills 16 outputs without a heap call") {
  // Outputs: ports 1 and 2 (ACN0, ACN1), then 13..26 (ACN2..ACN15) after the controls.
  const LV2_Descriptor* d = loadDescriptor(2);
  Host host;
  const LV2_URID sequence = host.map.map(&host, LV2_ATOM__Sequence);
  Instance x(d, host);
  std::vector<std::vector<float>> extra(14, std::vector<float>(kFrames, NAN));
  for (uint32_t c = 0; c < 14; ++c) d->connect_port(x.h, 13 + c, extra[c].data());
  d->activate(x.h);
  uint64_t heapCalls = 0;
  REQUIRE(runUntilPlaying(x, host, kDefaultScenePath, &heapCalls));
  std::vector<double> energy(16, 0.0);
  bool finite = true;
  for (int block = 0; block < 300; ++block) {
    x.clearAtoms(sequence);
    for (uint32_t i = 0; i < kFrames; ++i) x.in[i] = (block * kFrames + i) % 4800 == 0;
    {
      dpc::rt::AllocationScope scope;
      d->run(x.h, kFrames);
      heapCalls += scope.counts().total();
    }
    for (uint32_t c = 0; c < 16; ++c) {
      const float* out = c == 0 ? x.left : c == 1 ? x.right : extra[c - 2].data();
      for (uint32_t i = 0; i < kFrames; ++i) {
        finite = finite && std::isfinite(out[i]);
        energy[c] += double(out[i]) * out[i];
      }
    }
  }
  d->deactivate(x.h);
  CHECK(heapCalls == 0);
  CHECK(finite);  // every output written (they start as NaN)
  // Every spherical-harmonic channel carries some of the room's response: no channel is a
  // silent or unconnected port (the reverberant field reaches each from many directions).
  for (uint32_t c = 0; c < 16; ++c) {
    INFO("ACN" << c << " energy " << energy[c]);
    CHECK(energy[c] > 1e-4 * energy[0]);
  }
}

TEST_CASE("LV2 plugin: pose ports beyond their declared ranges are clamped, logged once") {
  const LV2_Descriptor* d = loadDescriptor();
  Host host;
  dpc::test::LogCapture capture;
  const auto features = host.with(&capture.feature);
  const LV2_URID sequence = host.map.map(&host, LV2_ATOM__Sequence);
  Instance x(d, host, features.data());
  d->activate(x.h);
  bool finite = true;
  uint64_t heapCalls = 0;
  for (int block = 0; block < 50; ++block) {
    x.clearAtoms(sequence);
    x.in[0] = 1.f;
    x.controls[4] = block % 2 ? 1e20f : -FLT_MAX;  // source_x: beyond the range every block
    x.controls[3] = block < 10 ? NAN : 180.f;      // listener_yaw: NaN for a while
    {
      dpc::rt::AllocationScope scope;
      d->run(x.h, kFrames);
      heapCalls += scope.counts().total();
    }
    if (host.pendingSize) runWorker(d, x.h, host);  // the report, off the audio thread
    for (uint32_t i = 0; i < kFrames; ++i)
      finite = finite && std::isfinite(x.left[i]) && std::isfinite(x.right[i]);
  }
  d->deactivate(x.h);
  CHECK(heapCalls == 0);
  CHECK(finite);
  // One report each, the worker's: the ports stayed out of range for many blocks.
  CHECK(host.scheduled == 1);
  const std::vector<std::string> reports = capture.containing("dpc: port ");
  REQUIRE(reports.size() == 2);
  CHECK(reports[0] ==
        "dpc: port listener_yaw: nan is outside its range [-180, 180]; clamped to 180 (logged "
        "once)\n");
  CHECK(reports[1] ==
        "dpc: port source_x: -3.40282e+38 is outside its range [-100, 100]; clamped to -100 "
        "(logged once)\n");
}

namespace {

/// A bundle folder holding the shipped default scene with `rays` rays per frame (the plugin
/// reads BUNDLE/scene/room.json; its binary stays where it was built).
void writeBundle(const std::filesystem::path& bundle, int rays) {
  namespace fs = std::filesystem;
  const fs::path shipped = fs::path(kBundle) / "scene";
  fs::create_directories(bundle / "scene");
  fs::copy_file(shipped / "shoebox.obj", bundle / "scene" / "shoebox.obj");
  std::ifstream in(shipped / "room.json");
  std::stringstream json;
  json << in.rdbuf();
  std::ofstream(bundle / "scene" / "room.json")
      << std::regex_replace(json.str(), std::regex("\"rays_per_frame\": *[0-9]+"),
                            "\"rays_per_frame\": " + std::to_string(rays));
}

/// Energy of one block of both outputs.
double blockEnergy(const Instance& x) {
  double e = 0.0;
  for (uint32_t i = 0; i < kFrames; ++i)
    e += double(x.left[i]) * x.left[i] + double(x.right[i]) * x.right[i];
  return e;
}

}  // namespace

TEST_CASE("LV2 plugin: instantiate returns before a heavy scene is built, silent until it plays") {
  // 100,000 rays per frame: the load (which computes the first frame) takes seconds on any
  // machine, so a first block that is not silent, or a notification before the load has
  // logged its end, could only come from a load done inside instantiate or activate.
  const LV2_Descriptor* d = loadDescriptor();
  Host host;
  dpc::test::LogCapture capture;
  const auto features = host.with(&capture.feature);
  const dpc::test::TempDir bundle("dpc_lv2_bundle");
  writeBundle(bundle.path(), 100000);
  const std::string path = bundle.path().string() + "/";
  Instance x(d, host, features.data(), path.c_str());
  d->activate(x.h);
  const LV2_URID sequence = host.map.map(&host, LV2_ATOM__Sequence);
  std::fill(std::begin(x.in), std::end(x.in), 0.5f);  // a loud dry input throughout
  for (int block = 0; block < 2; ++block) {
    x.clearAtoms(sequence);
    d->run(x.h, kFrames);
    CHECK(blockEnergy(x) == 0.0);
    CHECK(notifiedPath(x, host).empty());
  }
  CHECK(capture.containing("is loaded").empty());
  // Ready: the loader logs it, run() swaps the scene in and names it on the notify port.
  REQUIRE(runUntilPlaying(x, host, path + "scene/room.json"));
  CHECK(capture.containing(path + "scene/room.json is loaded (1 sources, 2 output channels)")
            .size() == 1);
  double energy = 0.0;
  for (int block = 0; block < 100 && energy == 0.0; ++block) {
    std::fill(std::begin(x.in), std::end(x.in), 0.5f);
    x.clearAtoms(sequence);
    d->run(x.h, kFrames);
    energy = blockEnergy(x);
  }
  CHECK(energy > 0.0);
  d->deactivate(x.h);
}

TEST_CASE("LV2 plugin: a scene that does not load is reported, the plugin stays silent") {
  const LV2_Descriptor* d = loadDescriptor();
  Host host;
  dpc::test::LogCapture capture;
  const auto features = host.with(&capture.feature);
  const dpc::test::TempDir bundle("dpc_lv2_bundle");
  writeBundle(bundle.path(), 2048);
  std::filesystem::remove(bundle.path() / "scene" / "shoebox.obj");
  const std::string path = bundle.path().string() + "/";
  const LV2_URID sequence = host.map.map(&host, LV2_ATOM__Sequence);
  {
    Instance x(d, host, features.data(), path.c_str());
    d->activate(x.h);
    for (int block = 0; block < 50; ++block) {
      std::fill(std::begin(x.in), std::end(x.in), 0.5f);
      x.clearAtoms(sequence);
      d->run(x.h, kFrames);
      CHECK(blockEnergy(x) == 0.0);
      CHECK(x.latency == 0.f);
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    d->deactivate(x.h);
  }  // cleanup waits for the load
  INFO("log: " << Catch::Detail::stringify(capture.containing("")));
  CHECK(capture.containing("shoebox.obj").size() >= 1);
  CHECK(capture.containing(path + "scene/room.json is not loaded").size() == 1);
}

TEST_CASE("LV2 plugin: the engine block is the host's nominal block length") {
  // A JACK-like period of 96 frames (not a power of two): the scene's block is 256, so without
  // the option every third or so run() would render a whole 256-frame block.
  const LV2_Descriptor* d = loadDescriptor();
  Host host;
  const int32_t nominal = 96;
  const LV2_Options_Option options[] = {
      {LV2_OPTIONS_INSTANCE, 0, host.map.map(&host, LV2_BUF_SIZE__nominalBlockLength),
       sizeof nominal, host.map.map(&host, LV2_ATOM__Int), &nominal},
      {LV2_OPTIONS_INSTANCE, 0, 0, 0, 0, nullptr}};
  LV2_Feature optionsFeature{LV2_OPTIONS__options, const_cast<LV2_Options_Option*>(options)};
  const auto features = host.with(&optionsFeature);
  const LV2_URID sequence = host.map.map(&host, LV2_ATOM__Sequence);
  Instance x(d, host, features.data());
  d->activate(x.h);
  uint64_t heapCalls = 0;
  REQUIRE(runUntilPlaying(x, host, kDefaultScenePath, &heapCalls));
  bool finite = true;
  double energy = 0.0;
  for (int block = 0; block < 2000; ++block) {
    x.clearAtoms(sequence);
    for (uint32_t i = 0; i < uint32_t(nominal); ++i)
      x.in[i] = (block * nominal + int(i)) % 4800 == 0;
    {
      dpc::rt::AllocationScope scope;
      d->run(x.h, uint32_t(nominal));
      heapCalls += scope.counts().total();
    }
    if (block % 100 == 0) std::this_thread::sleep_for(std::chrono::milliseconds(20));
    for (uint32_t i = 0; i < uint32_t(nominal); ++i) {
      finite = finite && std::isfinite(x.left[i]) && std::isfinite(x.right[i]);
      energy += double(x.left[i]) * x.left[i] + double(x.right[i]) * x.right[i];
    }
  }
  d->deactivate(x.h);
  CHECK(x.latency == float(nominal));  // one engine block: the host's period
  CHECK(heapCalls == 0);
  CHECK(finite);
  CHECK(energy > 1e-6);
}

TEST_CASE("LV2 plugin: a host rate that is no rate is refused, not replaced by the scene's") {
  // The options' sample_rate 0 means "keep the scene's": a host passing 0 or NaN must not get
  // a plugin playing at the scene's 48 kHz. A rate beyond the engine's range is refused by the
  // C API when the scene loads (in the background): reported, and the plugin stays silent.
  const LV2_Descriptor* d = loadDescriptor();
  Host host;
  for (const double rate : {0.0, 0.4, -48000.0, double(NAN), double(INFINITY), 1e12}) {
    INFO(rate);
    LV2_Handle h = d->instantiate(d, rate, kBundle, host.features);
    CHECK(h == nullptr);
    if (h) d->cleanup(h);
  }
  for (const double rate : {8000.0, 384000.0}) {
    INFO(rate);
    dpc::test::LogCapture capture;
    const auto features = host.with(&capture.feature);
    LV2_Handle h = d->instantiate(d, rate, kBundle, features.data());
    REQUIRE(h != nullptr);
    d->cleanup(h);  // waits for the load
    CHECK(capture.containing("sample_rate").size() == 1);
    CHECK(capture.containing("room.json is not loaded").size() == 1);
  }
  dpc::test::LogCapture capture;
  const auto features = host.with(&capture.feature);
  LV2_Handle h = d->instantiate(d, 16000.0, kBundle, features.data());
  REQUIRE(h != nullptr);
  d->cleanup(h);
  CHECK(capture.containing("room.json is loaded").size() == 1);
}

TEST_CASE("LV2 plugin: no thread of the plugin or of dpc is left after cleanup") {
  // A host unloads the plugin (and libdpc, TBB with it) after cleanup: a thread left running
  // there (the loader, a propagation thread, TBB's workers) runs unmapped code. The scene
  // swap, the worker's free and a second instance's life are all done before the count.
  const LV2_Descriptor* d = loadDescriptor();
  Host host;
  const int before = dpc::test::threadCount();
  {
    Instance x(d, host);
    d->activate(x.h);
    REQUIRE(runUntilPlaying(x, host, kDefaultScenePath));
    CHECK(dpc::test::threadCount() > before);  // the propagation thread and TBB's workers
    sendPatchSet(x, host, DPC_SOURCE_DIR "/scenes/shoebox.json");
    REQUIRE(runUntilPlaying(x, host, DPC_SOURCE_DIR "/scenes/shoebox.json"));
    runWorker(d, x.h, host);  // frees the scene it replaced
    {
      Instance y(d, host);  // instantiated and cleaned up without ever running
    }
    d->deactivate(x.h);
  }
  CHECK(dpc::test::threadCountSettled(before) == before);
}
