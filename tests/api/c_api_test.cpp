// The C API's contract (include/dpc/dpc.h): error codes and messages instead of exceptions,
// unsupported operations reported as such, process() output finite and counted; scenes built
// in code against the same scene from a file; impulse and energy responses read out.
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <glm/gtc/quaternion.hpp>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "dpc/dpc.h"
#include "dpc/dpc_version.h"
#include "scene/orientation.h"

TEST_CASE("C API: bad arguments and bad scene files give codes and a message naming the file") {
  dpc_engine* e = reinterpret_cast<dpc_engine*>(1);
  CHECK(dpc_engine_create_from_file(nullptr, nullptr, &e) == DPC_ERR_INVALID_ARGUMENT);
  CHECK(e == nullptr);
  CHECK(dpc_engine_create_from_file("x.json", nullptr, nullptr) == DPC_ERR_INVALID_ARGUMENT);
  CHECK(dpc_engine_create_from_file("/nonexistent/scene.json", nullptr, &e) == DPC_ERR_INPUT);
  CHECK(e == nullptr);
  CHECK(std::string(dpc_last_error()).find("/nonexistent/scene.json") != std::string::npos);
  CHECK(dpc_engine_start(nullptr) == DPC_ERR_INVALID_ARGUMENT);
  dpc_engine_destroy(nullptr);
}

TEST_CASE("C API: shoebox engine processes finite blocks, counts unsupported calls") {
  dpc_engine* e = nullptr;
  REQUIRE(dpc_engine_create_from_file(DPC_SOURCE_DIR "/scenes/shoebox.json", nullptr, &e) ==
          DPC_OK);
  const int block = dpc_engine_block_size(e), channels = dpc_engine_output_channels(e);
  CHECK(dpc_engine_sample_rate(e) == 48000);
  CHECK(block == 512);
  CHECK(dpc_engine_source_count(e) == 1);
  CHECK(dpc_engine_set_source_position(e, 0, 1.f, 1.f, 1.f) == DPC_OK);
  CHECK(dpc_engine_set_source_position(e, 1, 1.f, 1.f, 1.f) == DPC_ERR_INVALID_ARGUMENT);
  CHECK(dpc_engine_set_source_position(e, 0, INFINITY, 1.f, 1.f) == DPC_ERR_INVALID_ARGUMENT);
  const float identity[4] = {0.f, 0.f, 0.f, 1.f};
  CHECK(dpc_engine_object_count(e) == 0);
  CHECK(dpc_engine_set_object_pose(e, 0, 0.f, 0.f, 0.f, identity[0], identity[1], identity[2],
                                   identity[3]) == DPC_ERR_INVALID_ARGUMENT);
  CHECK(dpc_engine_latency_frames(e) == block);
  CHECK(dpc_engine_set_listener_pose(e, 0, NAN, 1.6f, 1.5f, 0.f, 0.f) == DPC_ERR_INVALID_ARGUMENT);
  CHECK(dpc_engine_set_listener_pose(e, 0, 3.5f, 1.6f, 1.5f, 90.f, 0.f) == DPC_OK);

  std::vector<float> buffer(size_t(block) * channels, 1.f);
  std::vector<float*> outputs;
  for (int c = 0; c < channels; ++c) outputs.push_back(buffer.data() + size_t(c) * block);
  for (int b = 0; b < 8; ++b)
    CHECK(dpc_engine_process(e, nullptr, outputs.data(), block) == DPC_OK);
  for (float v : buffer) REQUIRE(std::isfinite(v));
  // Other callback sizes are adapted (two half blocks make one engine block); sizes outside
  // 1..8192 render nothing and are counted.
  CHECK(dpc_engine_process(e, nullptr, outputs.data(), block / 2) == DPC_OK);
  CHECK(dpc_engine_process(e, nullptr, outputs.data(), block / 2) == DPC_OK);
  CHECK(dpc_engine_process(e, nullptr, outputs.data(), 0) == DPC_ERR_INVALID_ARGUMENT);
  CHECK(dpc_engine_process(e, nullptr, outputs.data(), 8193) == DPC_ERR_INVALID_ARGUMENT);
  dpc_stats s{};
  CHECK(dpc_engine_get_stats(e, &s) == DPC_ERR_VERSION);  // struct_size not set
  CHECK(s.blocks == 0);                                   // nothing written
  s.struct_size = sizeof(dpc_stats);
  REQUIRE(dpc_engine_get_stats(e, &s) == DPC_OK);
  CHECK(s.blocks == 9);
  CHECK(s.rejected_callbacks == 2);
  CHECK(s.cache_budget_bytes == 0);  // no propagation frame has run yet
  CHECK(s.rays_per_frame == 0);
  CHECK(dpc_engine_start(e) == DPC_OK);
  CHECK(dpc_engine_stop(e) == DPC_OK);
  dpc_engine_destroy(e);
}

namespace {

// A 10 x 3 x 7 m box (x 0..10, y 0..3 up, z 0..7), wound inward, materials walls/floor/ceiling.
const float kBoxVertices[] = {0, 0, 0, 10, 0, 0, 0, 3, 0, 10, 3, 0,
                              0, 0, 7, 10, 0, 7, 0, 3, 7, 10, 3, 7};
const uint32_t kBoxIndices[] = {0, 1, 5, 0, 5, 4,   // floor
                                2, 6, 7, 2, 7, 3,   // ceiling
                                0, 2, 3, 0, 3, 1,   // z = 0
                                4, 5, 7, 4, 7, 6,   // z = 7
                                0, 4, 6, 0, 6, 2,   // x = 0
                                1, 3, 7, 1, 7, 5};  // x = 10
const uint32_t kBoxMaterials[] = {1, 1, 2, 2, 0, 0, 0, 0, 0, 0, 0, 0};
const char* kMaterialNames[] = {"walls", "floor", "ceiling"};
const float kAbsorption[3][8] = {{0.15f, 0.15f, 0.10f, 0.06f, 0.04f, 0.04f, 0.05f, 0.05f},
                                 {0.03f, 0.03f, 0.09f, 0.25f, 0.31f, 0.33f, 0.44f, 0.44f},
                                 {0.20f, 0.20f, 0.15f, 0.10f, 0.08f, 0.04f, 0.02f, 0.02f}};
const float kScattering[3] = {0.2f, 0.2f, 0.1f};

// The same box as a scene file (JSON + OBJ) in a fresh folder; returns the JSON's path.
std::string writeBoxScene(const std::string& folder) {
  std::filesystem::create_directories(folder);
  std::ofstream obj(folder + "/box.obj");
  for (int v = 0; v < 8; ++v)
    obj << "v " << kBoxVertices[3 * v] << ' ' << kBoxVertices[3 * v + 1] << ' '
        << kBoxVertices[3 * v + 2] << '\n';
  for (int t = 0; t < 12; ++t) {
    if (t % 2 == 0) obj << "usemtl " << kMaterialNames[kBoxMaterials[t]] << '\n';
    obj << "f " << kBoxIndices[3 * t] + 1 << ' ' << kBoxIndices[3 * t + 1] + 1 << ' '
        << kBoxIndices[3 * t + 2] + 1 << '\n';
  }
  std::ofstream json(folder + "/box.json");
  json << "{\"mesh\": \"box.obj\", \"materials\": {";
  for (int m = 0; m < 3; ++m) {
    json << (m ? ", " : "") << '"' << kMaterialNames[m] << "\": {\"absorption\": [";
    for (int b = 0; b < 8; ++b) json << (b ? ", " : "") << kAbsorption[m][b];
    json << "], \"scattering\": " << kScattering[m] << '}';
  }
  json << "}, \"sources\": [{\"name\": \"s\", \"position\": [3, 1.6, 3.5]}],"
          " \"listener\": {\"position\": [7, 1.6, 3.5], \"radius\": 0.5},"
          " \"propagation\": {\"rays_per_frame\": 1024, \"max_order\": 50, \"seed\": 7},"
          " \"audio\": {\"sample_rate\": 48000, \"block_size\": 256, \"output\": \"stereo\"}}";
  return folder + "/box.json";
}

/// The folder `name` in the system's temporary folder.
std::string tempFolder(const std::string& name) {
  return std::filesystem::temp_directory_path().string() + "/" + name;
}

/// The JSON text of the box scene file that writeBoxScene writes in `folder`.
std::string boxSceneJson(const std::string& folder) {
  std::ifstream in(writeBoxScene(folder));
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

/// Options for a scene whose sources the host feeds (no signal file read).
dpc_engine_options hostOptions() {
  dpc_engine_options o;
  dpc_engine_options_init(&o);
  o.host_inputs_only = 1;
  return o;
}

dpc_scene_data boxData(std::vector<dpc_material>& materials, dpc_source& source) {
  dpc_scene_data d;
  dpc_scene_data_init(&d);
  materials.resize(3);
  for (int m = 0; m < 3; ++m) {
    materials[size_t(m)].name = kMaterialNames[m];
    for (int b = 0; b < DPC_BANDS; ++b) materials[size_t(m)].absorption[b] = kAbsorption[m][b];
    materials[size_t(m)].scattering = kScattering[m];
  }
  d.mesh = dpc_mesh{kBoxVertices, 8, kBoxIndices, 12, kBoxMaterials};
  d.materials = materials.data();
  d.material_count = 3;
  source = dpc_source{{3.f, 1.6f, 3.5f}, 0.f, nullptr, 0, 0};
  d.sources = &source;
  d.source_count = 1;
  d.listener_position[0] = 7.f;
  d.listener_position[1] = 1.6f;
  d.listener_position[2] = 3.5f;
  d.rays_per_frame = 1024;
  d.max_order = 50;
  d.seed = 7;
  d.block_size = 256;
  d.output = DPC_OUTPUT_STEREO;
  return d;
}

std::vector<float> copyIr(dpc_engine* e, int channel) {
  size_t length = 0;
  REQUIRE(dpc_engine_copy_impulse_response(e, 0, channel, nullptr, 0, &length, nullptr) == DPC_OK);
  std::vector<float> ir(length);
  REQUIRE(dpc_engine_copy_impulse_response(e, 0, channel, ir.data(), ir.size(), nullptr, nullptr) ==
          DPC_OK);
  return ir;
}

std::vector<float> copyEnergy(dpc_engine* e, double* binSeconds) {
  size_t bins = 0;
  REQUIRE(dpc_engine_copy_energy_response(e, 0, nullptr, 0, &bins, binSeconds, nullptr) == DPC_OK);
  std::vector<float> er(bins * DPC_BANDS);
  REQUIRE(dpc_engine_copy_energy_response(e, 0, er.data(), bins, nullptr, nullptr, nullptr) ==
          DPC_OK);
  return er;
}

}  // namespace

TEST_CASE("C API: a scene built in code equals the same scene from a file, bit for bit") {
  const std::string file = writeBoxScene(tempFolder("dpc_api_box"));
  const dpc_engine_options host = hostOptions();
  dpc_engine* fromFile = nullptr;
  REQUIRE(dpc_engine_create_from_file(file.c_str(), &host, &fromFile) == DPC_OK);
  std::vector<dpc_material> materials;
  dpc_source source;
  const dpc_scene_data data = boxData(materials, source);
  dpc_engine* fromData = nullptr;
  REQUIRE(dpc_engine_create_from_data(&data, nullptr, &fromData) == DPC_OK);
  CHECK(dpc_engine_output_channels(fromData) == 2);
  CHECK(dpc_engine_block_size(fromData) == 256);

  // Before any frame there is nothing to read.
  size_t length = 0;
  CHECK(dpc_engine_copy_impulse_response(fromData, 0, 0, nullptr, 0, &length, nullptr) ==
        DPC_ERR_STATE);
  CHECK(dpc_engine_copy_impulse_response(fromData, 0, 2, nullptr, 0, &length, nullptr) ==
        DPC_ERR_INVALID_ARGUMENT);
  // Three frames each (the diffuse path cache carries paths between them), same seed.
  for (int f = 0; f < 3; ++f) {
    REQUIRE(dpc_engine_step(fromFile) == DPC_OK);
    REQUIRE(dpc_engine_step(fromData) == DPC_OK);
  }
  for (int c = 0; c < 2; ++c) {
    const std::vector<float> a = copyIr(fromFile, c), b = copyIr(fromData, c);
    REQUIRE(a.size() == size_t(2.0 * 48000));  // ir_length 2 s (the default) at 48 kHz
    CHECK(a == b);
  }
  double binSeconds = 0.0;
  const std::vector<float> ea = copyEnergy(fromFile, &binSeconds);
  const std::vector<float> eb = copyEnergy(fromData, nullptr);
  CHECK(ea == eb);
  CHECK(binSeconds == 1e-3);
  // The direct sound, 4 m away, is in bin floor(4 m / c / 1 ms) with intensity 1/(4 pi r^2)
  // in 1/m^2 (inverse square law). At 63 Hz ISO 9613-1 air absorption over 4 m is 4e-4 dB and
  // the first reflection (floor, 5.1 m) arrives 3 ms later, so the bin holds the direct sound
  // alone to 0.1 %.
  const double c = 331.3 * std::sqrt(1.0 + 20.0 / 273.15);
  const size_t k = size_t(4.0 / c / binSeconds);
  const double expected = 1.0 / (4.0 * M_PI * 16.0);
  CHECK(ea[k * DPC_BANDS + 0] == Approx(expected).epsilon(1e-3));
  uint64_t frame = 0;
  REQUIRE(dpc_engine_copy_impulse_response(fromData, 0, 0, nullptr, 0, nullptr, &frame) == DPC_OK);
  CHECK(frame == 3);
  // step() traces the scene's rays every frame (no adaptation: same bits on any machine).
  dpc_stats stats{};
  stats.struct_size = sizeof(dpc_stats);
  REQUIRE(dpc_engine_get_stats(fromData, &stats) == DPC_OK);
  CHECK(stats.rays_per_frame == 1024);
  CHECK(stats.rays_per_frame_min == 1024);
  CHECK(stats.reduced_frames == 0);
  // step() is for a stopped engine only.
  REQUIRE(dpc_engine_start(fromData) == DPC_OK);
  CHECK(dpc_engine_step(fromData) == DPC_ERR_STATE);
  dpc_engine_destroy(fromData);
  dpc_engine_destroy(fromFile);
}

TEST_CASE("C API: ir_length seconds give ir_length x rate samples") {
  // The user's arithmetic is the oracle: 0.1 s at 48 kHz is 4800 samples. The length is a
  // float (0.1f is 0.100000001 s): its rounding must not add a sample. (The energy response's
  // 1 ms bins keep their count, ceil of the float length, one more here: a bake's shape and
  // settings hash are made of it, and bakes already written must still load.)
  struct Case {
    float seconds;
    int rate;
    size_t samples;
  };
  for (const Case& t :
       {Case{0.1f, 48000, 4800}, Case{0.3f, 44100, 13230}, Case{0.1f, 192000, 19200},
        Case{0.7f, 48000, 33600}, Case{0.2505f, 48000, 12024}}) {
    std::vector<dpc_material> materials;
    dpc_source source;
    const dpc_scene_data data = boxData(materials, source);
    dpc_engine_options o;
    dpc_engine_options_init(&o);
    o.ir_length = t.seconds;
    o.sample_rate = t.rate;
    o.rays_per_frame = 256;
    dpc_engine* e = nullptr;
    REQUIRE(dpc_engine_create_from_data(&data, &o, &e) == DPC_OK);
    REQUIRE(dpc_engine_step(e) == DPC_OK);
    size_t samples = 0;
    REQUIRE(dpc_engine_copy_impulse_response(e, 0, 0, nullptr, 0, &samples, nullptr) == DPC_OK);
    INFO(t.seconds << " s at " << t.rate << " Hz");
    CHECK(samples == t.samples);
    dpc_engine_destroy(e);
  }
}

TEST_CASE("C API: bad scene data names the field") {
  std::vector<dpc_material> materials;
  dpc_source source;
  dpc_scene_data data = boxData(materials, source);
  dpc_engine* e = reinterpret_cast<dpc_engine*>(1);
  materials[1].absorption[2] = 1.5f;
  CHECK(dpc_engine_create_from_data(&data, nullptr, &e) == DPC_ERR_INPUT);
  CHECK(e == nullptr);
  CHECK(std::string(dpc_last_error()).find("dpc_scene_data: materials[1].absorption[2]") == 0);
  materials[1].absorption[2] = 0.1f;
  const uint32_t badIndices[] = {0, 1, 8};
  data.mesh.indices = badIndices;
  data.mesh.triangle_count = 1;
  CHECK(dpc_engine_create_from_data(&data, nullptr, &e) == DPC_ERR_INPUT);
  CHECK(std::string(dpc_last_error()).find("mesh.indices[2]") != std::string::npos);
  data = boxData(materials, source);
  data.listener_radius = 0.f;
  CHECK(dpc_engine_create_from_data(&data, nullptr, &e) == DPC_ERR_INPUT);
  CHECK(std::string(dpc_last_error()).find("listener_radius") != std::string::npos);
  data = boxData(materials, source);
  dpc_engine_options o;
  dpc_engine_options_init(&o);
  o.sample_rate = 100;
  CHECK(dpc_engine_create_from_data(&data, &o, &e) == DPC_ERR_INVALID_ARGUMENT);
  CHECK(std::string(dpc_last_error()).find("sample_rate") != std::string::npos);
  CHECK(dpc_engine_create_from_data(nullptr, nullptr, &e) == DPC_ERR_INVALID_ARGUMENT);
}

// The listener is 4 m along +x from the source; its direct sound is bin k of the energy
// response alone (see above). A cardioid of the same power facing it is 10 lg 3 = +4.77 dB
// louder there (Q = 3, scene/directivity.h); turned away (half a turn about +y), its rear null
// leaves the bin empty.
TEST_CASE("C API: source_directivities carries a source's pattern and rotation") {
  std::vector<dpc_material> materials;
  dpc_source source;
  dpc_scene_data data = boxData(materials, source);
  auto directBin = [&](const dpc_source_directivity& d) {
    data.source_directivities = &d;
    dpc_engine* e = nullptr;
    REQUIRE(dpc_engine_create_from_data(&data, nullptr, &e) == DPC_OK);
    REQUIRE(dpc_engine_step(e) == DPC_OK);
    double binSeconds = 0.0;
    const std::vector<float> energy = copyEnergy(e, &binSeconds);
    dpc_engine_destroy(e);
    const double c = 331.3 * std::sqrt(1.0 + 20.0 / 273.15);
    return energy[size_t(4.0 / c / binSeconds) * DPC_BANDS + 0];
  };
  const double omni = 1.0 / (4.0 * M_PI * 16.0);
  dpc_source_directivity cardioid{{0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f}, {0, 0, 0, 1}};
  CHECK(directBin(cardioid) == Approx(3.0 * omni).epsilon(1e-3));
  cardioid.rotation[1] = 1.f;  // [0, 1, 0, 1]: a quarter turn about +y, normalised; side: 0.75
  CHECK(directBin(cardioid) == Approx(0.75 * omni).epsilon(1e-3));
  cardioid.rotation[3] = 0.f;  // [0, 1, 0, 0]: half a turn, facing -x
  CHECK(directBin(cardioid) < 1e-6 * omni);
  // At run time: the same half turn through dpc_engine_set_source_rotation, and back.
  {
    const dpc_source_directivity facing{{0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f},
                                        {0, 0, 0, 1}};
    data.source_directivities = &facing;
    dpc_engine* e = nullptr;
    REQUIRE(dpc_engine_create_from_data(&data, nullptr, &e) == DPC_OK);
    auto stepBin = [&] {
      REQUIRE(dpc_engine_step(e) == DPC_OK);
      double binSeconds = 0.0;
      const std::vector<float> energy = copyEnergy(e, &binSeconds);
      const double c = 331.3 * std::sqrt(1.0 + 20.0 / 273.15);
      return energy[size_t(4.0 / c / binSeconds) * DPC_BANDS + 0];
    };
    CHECK(stepBin() == Approx(3.0 * omni).epsilon(1e-3));
    CHECK(dpc_engine_set_source_rotation(e, 0, 0.f, 2.f, 0.f, 0.f) == DPC_OK);  // normalised
    CHECK(stepBin() < 1e-6 * omni);
    CHECK(dpc_engine_set_source_rotation(e, 0, 0.f, 0.f, 0.f, 0.f) == DPC_ERR_INVALID_ARGUMENT);
    CHECK(dpc_engine_set_source_rotation(e, 1, 0.f, 0.f, 0.f, 1.f) == DPC_ERR_INVALID_ARGUMENT);
    CHECK(dpc_engine_set_source_rotation(nullptr, 0, 0.f, 0.f, 0.f, 1.f) ==
          DPC_ERR_INVALID_ARGUMENT);
    CHECK(dpc_engine_set_source_rotation(e, 0, 0.f, 0.f, 0.f, 1.f) == DPC_OK);
    CHECK(stepBin() == Approx(3.0 * omni).epsilon(1e-3));
    dpc_engine_destroy(e);
  }
  cardioid.rotation[1] = 0.f;  // zero length
  data.source_directivities = &cardioid;
  dpc_engine* e = nullptr;
  CHECK(dpc_engine_create_from_data(&data, nullptr, &e) == DPC_ERR_INPUT);
  CHECK(std::string(dpc_last_error()).find("dpc_scene_data: source_directivities[0].rotation") ==
        0);
}

TEST_CASE("C API: several listeners share a frame, the selected one is heard and read out") {
  // The box scene with two listeners: "a" 4 m from the source, "b" 6 m from it.
  const std::string folder = tempFolder("dpc_api_two");
  std::string json = boxSceneJson(folder);
  const std::string one = "\"listener\": {\"position\": [7, 1.6, 3.5], \"radius\": 0.5}";
  const size_t at = json.find(one);
  REQUIRE(at != std::string::npos);
  json.replace(at, one.size(),
               "\"listeners\": [{\"name\": \"a\", \"position\": [7, 1.6, 3.5], \"radius\": 0.5},"
               " {\"name\": \"b\", \"position\": [9, 1.6, 3.5], \"radius\": 0.5}]");
  const std::string file = folder + "/two.json";
  std::ofstream(file) << json;

  const dpc_engine_options host = hostOptions();
  dpc_engine *e = nullptr, *moved = nullptr;
  REQUIRE(dpc_engine_create_from_file(file.c_str(), &host, &e) == DPC_OK);
  REQUIRE(dpc_engine_create_from_file(file.c_str(), &host, &moved) == DPC_OK);
  CHECK(dpc_engine_listener_count(e) == 2);
  CHECK(dpc_engine_selected_listener(e) == 0);
  CHECK(dpc_engine_select_listener(e, 2) == DPC_ERR_INVALID_ARGUMENT);
  CHECK(dpc_engine_select_listener(e, -1) == DPC_ERR_INVALID_ARGUMENT);
  CHECK(dpc_engine_set_listener_pose(e, 2, 1.f, 1.f, 1.f, 0.f, 0.f) == DPC_ERR_INVALID_ARGUMENT);
  CHECK(dpc_engine_set_listener_pose(e, 1, NAN, 1.f, 1.f, 0.f, 0.f) == DPC_ERR_INVALID_ARGUMENT);

  // Selecting "b" makes the read-out (and what process() plays) b's: its direct sound is 6 m
  // away, in bin floor(6 m / c / 1 ms) at 1/(4 pi 6^2) (63 Hz: air absorption 6e-4 dB, the
  // first reflection 1.2 ms later in the next bin), and a's bin at 4 m holds nothing direct.
  REQUIRE(dpc_engine_select_listener(e, 1) == DPC_OK);
  CHECK(dpc_engine_selected_listener(e) == 1);
  REQUIRE(dpc_engine_step(e) == DPC_OK);
  double binSeconds = 0.0;
  const std::vector<float> eb = copyEnergy(e, &binSeconds);
  const double c = 331.3 * std::sqrt(1.0 + 20.0 / 273.15);
  const size_t k6 = size_t(6.0 / c / binSeconds), k4 = size_t(4.0 / c / binSeconds);
  CHECK(eb[k6 * DPC_BANDS] == Approx(1.0 / (4.0 * M_PI * 36.0)).epsilon(1e-3));
  CHECK(eb[k4 * DPC_BANDS] < 1e-3 / (4.0 * M_PI * 16.0));

  // Listener "b" moved onto "a" and selected gets exactly a's response: both are traced with
  // the same rays in one pass, only the listener index in the path identifiers differs.
  REQUIRE(dpc_engine_set_listener_pose(moved, 1, 7.f, 1.6f, 3.5f, 0.f, 0.f) == DPC_OK);
  REQUIRE(dpc_engine_select_listener(e, 0) == DPC_OK);
  REQUIRE(dpc_engine_select_listener(moved, 1) == DPC_OK);
  for (int f = 0; f < 2; ++f) {
    REQUIRE(dpc_engine_step(moved) == DPC_OK);
    if (f) REQUIRE(dpc_engine_step(e) == DPC_OK);
  }
  // e has run two frames with both listeners where the scene puts them; so has `moved`, with b
  // on a: a's response in e and b's in `moved` come from the same rays and the same frames.
  CHECK(copyEnergy(e, nullptr) == copyEnergy(moved, nullptr));
  dpc_engine_destroy(moved);
  dpc_engine_destroy(e);

  // The same two listeners built in code: listener 1 is additional_listeners[0]; selected, its
  // response equals the file scene's "b" bit for bit.
  std::vector<dpc_material> materials;
  dpc_source source;
  dpc_scene_data data = boxData(materials, source);
  const dpc_listener b = {{9.f, 1.6f, 3.5f}, 0.5f, 0.f, 0.f, 0.f};
  data.additional_listeners = &b;
  data.additional_listener_count = 1;
  dpc_engine *fromData = nullptr, *fromFile = nullptr;
  REQUIRE(dpc_engine_create_from_data(&data, nullptr, &fromData) == DPC_OK);
  REQUIRE(dpc_engine_create_from_file(file.c_str(), &host, &fromFile) == DPC_OK);
  CHECK(dpc_engine_listener_count(fromData) == 2);
  for (dpc_engine* x : {fromData, fromFile}) {
    REQUIRE(dpc_engine_select_listener(x, 1) == DPC_OK);
    REQUIRE(dpc_engine_step(x) == DPC_OK);
  }
  CHECK(copyEnergy(fromData, nullptr) == copyEnergy(fromFile, nullptr));
  dpc_engine_destroy(fromFile);
  dpc_engine_destroy(fromData);
  data.additional_listener_count = 64;
  dpc_engine* none = nullptr;
  CHECK(dpc_engine_create_from_data(&data, nullptr, &none) == DPC_ERR_INPUT);
  CHECK(std::string(dpc_last_error()).find("additional_listener_count") != std::string::npos);
}

TEST_CASE("C API: the library's version is the header's") {
  CHECK(dpc_version() == DPC_VERSION);
  CHECK(DPC_VERSION == DPC_MAKE_VERSION(DPC_VERSION_MAJOR, DPC_VERSION_MINOR, DPC_VERSION_PATCH));
  CHECK(DPC_MAKE_VERSION(0, 2, 0) > DPC_MAKE_VERSION(0, 1, 9));
  CHECK(std::string(DPC_VERSION_STRING) == std::to_string(DPC_VERSION_MAJOR) + "." +
                                               std::to_string(DPC_VERSION_MINOR) + "." +
                                               std::to_string(DPC_VERSION_PATCH));
}

TEST_CASE("C API: a struct of another layout gives DPC_ERR_VERSION, not a read past it") {
  dpc_engine_options o;
  dpc_engine_options_init(&o);
  CHECK(o.struct_size == sizeof(dpc_engine_options));
  dpc_engine* e = reinterpret_cast<dpc_engine*>(1);
  o.struct_size = sizeof(dpc_engine_options) - sizeof(int);  // a caller of an older dpc.h
  CHECK(dpc_engine_create_from_file(DPC_SOURCE_DIR "/scenes/shoebox.json", &o, &e) ==
        DPC_ERR_VERSION);
  CHECK(e == nullptr);
  CHECK(std::string(dpc_last_error()).find("dpc_engine_options.struct_size") == 0);
  std::vector<dpc_material> materials;
  dpc_source source;
  dpc_scene_data data = boxData(materials, source);
  CHECK(data.struct_size == sizeof(dpc_scene_data));
  data.struct_size = 0;  // never initialised by dpc_scene_data_init
  CHECK(dpc_engine_create_from_data(&data, nullptr, &e) == DPC_ERR_VERSION);
  CHECK(std::string(dpc_last_error()).find("dpc_scene_data.struct_size") == 0);
  data.struct_size = sizeof(dpc_scene_data);
  o.struct_size = sizeof(dpc_engine_options) + 8;  // a caller of a newer dpc.h
  CHECK(dpc_engine_create_from_data(&data, &o, &e) == DPC_ERR_VERSION);
  CHECK(e == nullptr);
}

namespace {

struct LoggedLines {
  std::vector<std::pair<dpc_log_level, std::string>> lines;
};

void collect(dpc_log_level level, const char* message, void* user) {
  static_cast<LoggedLines*>(user)->lines.emplace_back(level, message);
}

}  // namespace

TEST_CASE("C API: a scene file's warnings reach the log callback") {
  // The box scene with one more material that no triangle uses: the loader warns about it.
  const std::string folder = tempFolder("dpc_api_log");
  std::string json = boxSceneJson(folder);
  const std::string key = "\"materials\": {";
  REQUIRE(json.find(key) != std::string::npos);
  json.insert(json.find(key) + key.size(),
              "\"spare\": {\"absorption\": [0.1, 0.1, 0.1, 0.1, 0.1, 0.1, 0.1, 0.1], "
              "\"scattering\": 0.1}, ");
  const std::string file = folder + "/spare.json";
  std::ofstream(file) << json;
  LoggedLines logged;
  dpc_set_log_callback(&collect, &logged);
  const dpc_engine_options host = hostOptions();
  dpc_engine* e = nullptr;
  REQUIRE(dpc_engine_create_from_file(file.c_str(), &host, &e) == DPC_OK);
  dpc_engine_destroy(e);
  REQUIRE(logged.lines.size() == 1);
  CHECK(logged.lines[0].first == DPC_LOG_WARNING);
  CHECK(logged.lines[0].second.find("materials.spare: not used") != std::string::npos);
  // A replaced callback is called no more.
  LoggedLines later;
  dpc_set_log_callback(&collect, &later);
  REQUIRE(dpc_engine_create_from_file(file.c_str(), &host, &e) == DPC_OK);
  dpc_engine_destroy(e);
  dpc_set_log_callback(nullptr, nullptr);  // the default: stderr
  CHECK(logged.lines.size() == 1);
  CHECK(later.lines.size() == 1);
}

TEST_CASE("C API: a quaternion's yaw, pitch and roll give the listener the quaternion's axes") {
  float yaw = 0.f, pitch = 0.f, roll = 0.f;
  const float h = std::sqrt(0.5f);
  // 90 degrees about +x (the rest pose's forward) turns +y to +z, its right: roll +90.
  REQUIRE(dpc_yaw_pitch_roll_from_quaternion(h, 0.f, 0.f, h, &yaw, &pitch, &roll) == DPC_OK);
  CHECK(yaw == Approx(0.f).margin(1e-4));
  CHECK(pitch == Approx(0.f).margin(1e-4));
  CHECK(roll == Approx(90.f).margin(1e-4));
  // Random head quaternions: the listener's forward and up are R(q) x and R(q) y.
  std::mt19937 rng(7);
  std::normal_distribution<float> g;
  for (int i = 0; i < 200; ++i) {
    const glm::quat q = glm::normalize(glm::quat(g(rng), g(rng), g(rng), g(rng)));
    REQUIRE(dpc_yaw_pitch_roll_from_quaternion(q.x, q.y, q.z, q.w, &yaw, &pitch, &roll) == DPC_OK);
    const float k = 3.14159265f / 180.f;
    const dpc::Orientation o{yaw * k, pitch * k, roll * k};
    CHECK(glm::length(o.forward() - q * glm::vec3(1.f, 0.f, 0.f)) < 1e-4f);
    CHECK(glm::length(o.up() - q * glm::vec3(0.f, 1.f, 0.f)) < 1e-4f);
    CHECK(std::abs(roll) <= 180.f);
  }
  CHECK(dpc_yaw_pitch_roll_from_quaternion(0.f, 0.f, 0.f, 1.f, &yaw, &pitch, nullptr) ==
        DPC_ERR_INVALID_ARGUMENT);
}

TEST_CASE("C API: a quaternion in the API's frame gives the listener's yaw and pitch") {
  float yaw = 1.f, pitch = 1.f;
  const float h = std::sqrt(0.5f);
  CHECK(dpc_yaw_pitch_from_quaternion(0.f, 0.f, 0.f, 1.f, &yaw, &pitch) == DPC_OK);
  CHECK(yaw == 0.f);
  CHECK(pitch == 0.f);
  // 90 degrees about +y turns +x towards -z: a left turn, yaw +90.
  CHECK(dpc_yaw_pitch_from_quaternion(0.f, h, 0.f, h, &yaw, &pitch) == DPC_OK);
  CHECK(yaw == Approx(90.f).margin(1e-4));
  CHECK(pitch == Approx(0.f).margin(1e-4));
  // 30 degrees about +z raises +x towards +y: pitch +30; not normalised on input.
  const float s = std::sin(15.f * 3.14159265f / 180.f), c = std::cos(15.f * 3.14159265f / 180.f);
  CHECK(dpc_yaw_pitch_from_quaternion(0.f, 0.f, 2.f * s, 2.f * c, &yaw, &pitch) == DPC_OK);
  CHECK(yaw == Approx(0.f).margin(1e-4));
  CHECK(pitch == Approx(30.f).margin(1e-4));
  // Roll (about the forward axis +x) is dropped.
  CHECK(dpc_yaw_pitch_from_quaternion(h, 0.f, 0.f, h, &yaw, &pitch) == DPC_OK);
  CHECK(yaw == Approx(0.f).margin(1e-4));
  CHECK(pitch == Approx(0.f).margin(1e-4));
  CHECK(dpc_yaw_pitch_from_quaternion(0.f, 0.f, 0.f, 0.f, &yaw, &pitch) ==
        DPC_ERR_INVALID_ARGUMENT);
  CHECK(dpc_yaw_pitch_from_quaternion(NAN, 0.f, 0.f, 1.f, &yaw, &pitch) ==
        DPC_ERR_INVALID_ARGUMENT);
  CHECK(dpc_yaw_pitch_from_quaternion(0.f, 0.f, 0.f, 1.f, nullptr, &pitch) ==
        DPC_ERR_INVALID_ARGUMENT);
}
