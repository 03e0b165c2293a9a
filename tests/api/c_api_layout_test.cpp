// The C API's growth rule (include/dpc/dpc.h, "Versions and growth rule"): a caller compiled
// against an earlier release hands over its structs of that release's layout, declared here
// as the released headers declared them (0.5.0: git show daecec5^:include/dpc/dpc.h; 0.6.0:
// git show 0029ebc:include/dpc/dpc.h; 0.7.0: git show 097ab2e:include/dpc/dpc.h; 0.8.0:
// git show 209b1ff:include/dpc/dpc.h, whose dpc_stats ends where max_order_energy_fraction
// begins). The library must read no byte past their struct_size, write none past it, give
// the fields they lack their defaults, and refuse any other size.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <iterator>
#include <string>
#include <vector>

#include "dpc/dpc.h"
#include "tests/api/box_data.h"

namespace {

using dpc::test::BoxData;

struct StatsV050 {
  size_t struct_size;
  uint64_t frames;
  double frame_ms, rays_per_second;
  uint64_t cache_entries, cache_bytes, cache_budget_bytes, cache_merged_entries;
  double cache_merged_energy_fraction;
  uint64_t irs_applied, irs_dropped;
  double ir_age_ms;
  uint64_t blocks, nan_blocks, late_callbacks, rejected_callbacks;
  int32_t rays_per_frame, rays_per_frame_min;
  uint64_t reduced_frames, baked_responses, bake_fallbacks;
};

struct StatsV060 : StatsV050 {
  uint64_t input_samples_replaced, limited_frames;
};

struct OptionsV060 {
  size_t struct_size;
  int sample_rate, block_size, rays_per_frame;
  dpc_output_format output;
  int host_inputs_only, ambisonic_order;
};

struct SceneDataV060 {
  size_t struct_size;
  dpc_mesh mesh;
  const dpc_material* materials;
  int material_count;
  const dpc_source* sources;
  int source_count;
  float listener_position[3], listener_radius, listener_yaw_degrees, listener_pitch_degrees,
      listener_roll_degrees;
  int rays_per_frame, max_order;
  float patch_size, cache_tau, frame_rate, ir_length;
  uint64_t seed;
  float speed_of_sound, temperature, humidity;
  int air_absorption, diffraction, sample_rate, block_size;
  dpc_output_format output;
  const dpc_listener* additional_listeners;
  int additional_listener_count;
  const dpc_source_directivity* source_directivities;
  float cache_pool_mb;
  dpc_rendering rendering;
  int late_buses;
  float cluster_angle_degrees;
  int ambisonic_order;
};

struct SceneDataV070 : SceneDataV060 {
  const dpc_material_transmission* material_transmissions;
  int exact_order;
};

constexpr unsigned char kCanary = 0xA5;

/// An old-layout struct followed in memory by bytes a library must neither read nor write:
/// `after` holds kCanary (for writes) or 0xFF (garbage that would fail validation if read).
template <class Old>
struct Guarded {
  union {
    Old old;
    unsigned char bytes[sizeof(Old) + 64];
  };
  explicit Guarded(unsigned char after = kCanary) { std::memset(bytes, after, sizeof bytes); }
  bool afterIntact(unsigned char after = kCanary) const {
    for (size_t i = sizeof(Old); i < sizeof bytes; ++i)
      if (bytes[i] != after) return false;
    return true;
  }
};

/// The box's scene data as a 0.6.0 caller would hand it over (the same values), with garbage
/// after its struct_size bytes.
Guarded<SceneDataV060> oldBox(BoxData& box) {
  Guarded<SceneDataV060> g(0xFF);
  std::memcpy(&g.old, &box.data(), sizeof(SceneDataV060));
  g.old.struct_size = sizeof(SceneDataV060);
  return g;
}

/// The box's scene data as a 0.7.0 caller would hand it over, with garbage in its tail
/// padding (0.8.0's reserved_0_7) and after its struct_size bytes.
Guarded<SceneDataV070> oldBox070(BoxData& box) {
  Guarded<SceneDataV070> g(0xFF);
  std::memcpy(&g.old, &box.data(), offsetof(dpc_scene_data, reserved_0_7));
  g.old.struct_size = sizeof(SceneDataV070);
  return g;
}

/// Source 0's impulse response after two frames of an engine from `data` and `options`.
std::vector<float> responseOf(const void* data, const void* options) {
  dpc_engine* e = nullptr;
  REQUIRE(dpc_engine_create_from_data(static_cast<const dpc_scene_data*>(data),
                                      static_cast<const dpc_engine_options*>(options),
                                      &e) == DPC_OK);
  REQUIRE(dpc_engine_step(e) == DPC_OK);
  REQUIRE(dpc_engine_step(e) == DPC_OK);
  size_t n = 0;
  REQUIRE(dpc_engine_copy_impulse_response(e, 0, 0, nullptr, 0, &n, nullptr) == DPC_OK);
  std::vector<float> ir(n);
  REQUIRE(dpc_engine_copy_impulse_response(e, 0, 0, ir.data(), n, nullptr, nullptr) == DPC_OK);
  dpc_engine_destroy(e);
  return ir;
}

bool messageHas(const std::string& text) {
  return std::string(dpc_last_error()).find(text) != std::string::npos;
}

}  // namespace

TEST_CASE("Growth rule: dpc_stats of 0.5.0 and 0.6.0 get their own fields, nothing past them") {
  BoxData box;
  dpc_engine* e = nullptr;
  REQUIRE(dpc_engine_create_from_data(&box.data(), nullptr, &e) == DPC_OK);
  for (int i = 0; i < 3; ++i) REQUIRE(dpc_engine_step(e) == DPC_OK);
  dpc_stats now{};
  now.struct_size = sizeof now;
  REQUIRE(dpc_engine_get_stats(e, &now) == DPC_OK);
  CHECK(now.frames == 3);
  Guarded<StatsV050> v050;
  v050.old.struct_size = sizeof(StatsV050);
  REQUIRE(dpc_engine_get_stats(e, reinterpret_cast<dpc_stats*>(&v050.old)) == DPC_OK);
  CHECK(v050.afterIntact());
  CHECK(v050.old.struct_size == sizeof(StatsV050));
  CHECK(v050.old.frames == 3);
  CHECK(v050.old.cache_entries == now.cache_entries);
  CHECK(v050.old.cache_budget_bytes == now.cache_budget_bytes);
  CHECK(v050.old.irs_applied == now.irs_applied);
  CHECK(v050.old.rays_per_frame == now.rays_per_frame);
  CHECK(v050.old.bake_fallbacks == now.bake_fallbacks);
  Guarded<StatsV060> v060;
  v060.old.struct_size = sizeof(StatsV060);
  REQUIRE(dpc_engine_get_stats(e, reinterpret_cast<dpc_stats*>(&v060.old)) == DPC_OK);
  CHECK(v060.afterIntact());
  CHECK(v060.old.frames == 3);
  CHECK(v060.old.rays_per_frame_min == now.rays_per_frame_min);
  CHECK(v060.old.limited_frames == now.limited_frames);
  dpc_engine_destroy(e);
}

TEST_CASE("Growth rule: dpc_scene_data and options of 0.6.0 are read to their size, new fields "
          "at their defaults") {
  BoxData box;
  const std::vector<float> current = responseOf(&box.data(), nullptr);
  REQUIRE(!current.empty());
  // 0xFF after the old structs: read as exact_order -1, or as a material_transmissions
  // pointer, the engine could not be built; read as ir_length, NaN.
  const Guarded<SceneDataV060> data = oldBox(box);
  CHECK(responseOf(&data.old, nullptr) == current);
  Guarded<OptionsV060> options(0xFF);
  std::memset(&options.old, 0, sizeof options.old);
  options.old.struct_size = sizeof(OptionsV060);
  CHECK(responseOf(&data.old, &options.old) == current);
  CHECK(data.afterIntact(0xFF));
  CHECK(options.afterIntact(0xFF));
}

TEST_CASE("Growth rule: the fields 0.7.0 appended take effect for a caller that has them") {
  BoxData box;
  const std::vector<float> byDefault = responseOf(&box.data(), nullptr);
  dpc_engine_options o;
  dpc_engine_options_init(&o);
  o.ir_length = 0.25f;
  CHECK(responseOf(&box.data(), &o).size() == size_t(0.25f * float(box.d.sample_rate)));
  // What a 50 ms response leaves out (dpc_stats.dropped_energy_fraction): Sabine's T60 of the
  // box (V 72 m^3, A = 0.1 x 108 m^2) is 1.07 s, so exp(-13.8 x 0.05 / 1.07) = 0.52 of the
  // reverberant energy, which outweighs the direct sound 20 to 1, arrives later; a 1 s
  // response keeps all but exp(-12.9) = 3e-6 of it (the reflection order caps it sooner).
  auto dropped = [&](float irLength) {
    o.ir_length = irLength;
    dpc_engine* e = nullptr;
    REQUIRE(dpc_engine_create_from_data(&box.data(), &o, &e) == DPC_OK);
    for (int i = 0; i < 3; ++i) REQUIRE(dpc_engine_step(e) == DPC_OK);
    dpc_stats s{};
    s.struct_size = sizeof s;
    REQUIRE(dpc_engine_get_stats(e, &s) == DPC_OK);
    dpc_engine_destroy(e);
    return s.dropped_energy_fraction;
  };
  const double lost = dropped(0.05f);
  CHECK(lost > 0.3);
  CHECK(lost < 0.75);
  CHECK(dropped(1.f) < 1e-3);
  box.d.exact_order = 0;  // no exact early paths: another response for the same seed
  CHECK(responseOf(&box.data(), nullptr) != byDefault);
  box.d.exact_order = 3;
  dpc_material_transmission loss;
  for (float& r : loss.loss_db) r = INFINITY;  // opaque: the default's response
  box.d.material_transmissions = &loss;
  CHECK(responseOf(&box.data(), nullptr) == byDefault);
  loss.loss_db[7] = 250.f;  // beyond the limit
  dpc_engine* e = nullptr;
  CHECK(dpc_engine_create_from_data(&box.data(), nullptr, &e) == DPC_ERR_INPUT);
  CHECK(messageHas("material_transmissions[0].loss_db[7]"));
  for (float& r : loss.loss_db) r = 20.f;  // tau = 0.01 <= absorption 0.1: the walls leak
  CHECK(responseOf(&box.data(), nullptr) != byDefault);
}

TEST_CASE("Growth rule: dpc_scene_data of 0.7.0 is read to its size, 0.8.0's fields at their "
          "defaults, its tail padding ignored") {
  static_assert(sizeof(SceneDataV070) == offsetof(dpc_scene_data, estimator));
  BoxData box;
  const std::vector<float> current = responseOf(&box.data(), nullptr);
  REQUIRE(!current.empty());
  // 0xFF in the padding and after: read as estimator or tracing, an unknown value (refused);
  // as roulette_threshold_db, NaN (refused).
  const Guarded<SceneDataV070> data = oldBox070(box);
  CHECK(responseOf(&data.old, nullptr) == current);
  CHECK(data.afterIntact(0xFF));
}

TEST_CASE("Growth rule: the fields 0.8.0 appended take effect for a caller that has them") {
  BoxData box;
  const std::vector<float> dpcResponse = responseOf(&box.data(), nullptr);
  CHECK(box.d.estimator == DPC_ESTIMATOR_DPC);
  CHECK(box.d.tracing == DPC_TRACING_AUTO);
  CHECK(box.d.reflection_scattering == 1);
  CHECK(box.d.roulette_threshold_db == -60.f);  // docs/scene-format.md's defaults
  // The thesis's definition: the DPC with tau = 0 is plain path tracing, bit for bit; the
  // second frame of the DPC with tau 1 s holds the first frame's paths too.
  box.d.estimator = DPC_ESTIMATOR_PATH_TRACING;
  const std::vector<float> traced = responseOf(&box.data(), nullptr);
  CHECK(traced != dpcResponse);
  box.d.estimator = DPC_ESTIMATOR_DPC;
  box.d.cache_tau = 0.f;
  CHECK(responseOf(&box.data(), nullptr) == traced);
  box.d.cache_tau = 1.f;
  // One source, one listener: AUTO traces from the source.
  box.d.tracing = DPC_TRACING_FROM_SOURCES;
  CHECK(responseOf(&box.data(), nullptr) == dpcResponse);
  box.d.tracing = DPC_TRACING_FROM_LISTENERS;
  CHECK(responseOf(&box.data(), nullptr) != dpcResponse);
  box.d.tracing = DPC_TRACING_AUTO;
  // alpha 0.1 and 50 reflections leave 0.9^50 = -23 dB: a -60 dB roulette never acts, -10 dB
  // from the 22nd reflection on.
  box.d.roulette_threshold_db = -10.f;
  CHECK(responseOf(&box.data(), nullptr) != dpcResponse);
  box.d.roulette_threshold_db = -60.f;
  CHECK(responseOf(&box.data(), nullptr) == dpcResponse);
}

TEST_CASE("0.8.0's reflection_scattering acts on a free-standing face only") {
  BoxData box;
  auto differs = [&box] {
    box.d.reflection_scattering = 1;
    const std::vector<float> on = responseOf(&box.data(), nullptr);
    box.d.reflection_scattering = 0;
    const bool d = responseOf(&box.data(), nullptr) != on;
    box.d.reflection_scattering = 1;
    return d;
  };
  CHECK_FALSE(differs());  // the box's walls face no free space: no face scatters
  // A 0.6 m square sheet (both windings) 1 m above source and listener: a first-order
  // reflector far smaller than its Fresnel zone at low frequencies.
  const float plate[] = {2.7f, 2.5f, 1.7f, 3.3f, 2.5f, 1.7f, 3.3f, 2.5f, 2.3f, 2.7f, 2.5f, 2.3f};
  box.vertices.insert(box.vertices.end(), std::begin(plate), std::end(plate));
  for (const uint32_t i : {8, 9, 10, 8, 10, 11, 8, 10, 9, 8, 11, 10}) box.indices.push_back(i);
  box.materials.resize(box.indices.size() / 3, 0);
  CHECK(differs());
  box.d.diffraction = 0;  // the share needs the free edges diffraction finds
  CHECK_FALSE(differs());
}

// Oracle as in propagation_test: in a closed box of one absorption a in every band and no air,
// every ray meets its (N+1)-th wall with (1 - a)^N of its energy whatever path it took, so the
// share the order bound ends is (1 - a)^N (float sums: relative 1e-4). At the default bound of
// 200 the expectation is 0.9^200 = 7e-10, carried by the few rays Russian roulette let through
// with 10^k times their energy: a draw reads a small multiple of it, so the bound 1e-6 (100
// times under the warning) holds and an order cut miscounted as roulette's ends would not.
TEST_CASE("0.9.0's max_order_energy_fraction is the share the reflection order bound cut") {
  BoxData box;
  box.d.air_absorption = 0;
  auto cut = [&](int maxOrder) {
    box.d.max_order = maxOrder;
    box.d.exact_order = std::min(box.d.exact_order, maxOrder);
    dpc_engine* e = nullptr;
    REQUIRE(dpc_engine_create_from_data(&box.data(), nullptr, &e) == DPC_OK);
    REQUIRE(dpc_engine_step(e) == DPC_OK);
    dpc_stats s{};
    s.struct_size = sizeof s;
    REQUIRE(dpc_engine_get_stats(e, &s) == DPC_OK);
    dpc_engine_destroy(e);
    return s.max_order_energy_fraction;
  };
  for (const int n : {2, 8}) {
    INFO("max_order " << n);
    CHECK(cut(n) == Approx(std::pow(0.9, n)).epsilon(1e-4));
    CHECK(cut(n) > DPC_MAX_ORDER_WARN_FRACTION);
  }
  CHECK(cut(200) < 1e-6);
  // A 0.8.0 caller's struct ends before the field: nothing written there.
  Guarded<dpc_stats> old;
  old.old.struct_size = offsetof(dpc_stats, max_order_energy_fraction);
  dpc_engine* e = nullptr;
  REQUIRE(dpc_engine_create_from_data(&box.data(), nullptr, &e) == DPC_OK);
  REQUIRE(dpc_engine_step(e) == DPC_OK);
  CHECK(dpc_engine_get_stats(e, &old.old) == DPC_OK);
  CHECK(old.old.frames == 1);
  CHECK(old.bytes[offsetof(dpc_stats, max_order_energy_fraction)] == kCanary);
  CHECK(old.afterIntact());
  dpc_engine_destroy(e);
}

TEST_CASE("0.8.0's fields out of range are refused, naming the field") {
  BoxData box;
  dpc_engine* e = nullptr;
  const auto refused = [&](const char* field) {
    const dpc_status s = dpc_engine_create_from_data(&box.data(), nullptr, &e);
    return s == DPC_ERR_INPUT && e == nullptr && messageHas(std::string("dpc_scene_data: ") + field);
  };
  std::memset(&box.d.estimator, 0x7F, sizeof box.d.estimator);
  CHECK(refused("estimator"));
  box.d.estimator = DPC_ESTIMATOR_DPC;
  std::memset(&box.d.tracing, 0x7F, sizeof box.d.tracing);
  CHECK(refused("tracing"));
  box.d.tracing = DPC_TRACING_AUTO;
  for (const float db : {1.f, -301.f, NAN}) {
    box.d.roulette_threshold_db = db;
    CHECK(refused("roulette_threshold_db"));
  }
}

TEST_CASE("Growth rule: _init fills the caller's layout, the 0.6.0 entry points 0.6.0's") {
  dpc_scene_data current;
  dpc_scene_data_init(&current);
  CHECK(current.struct_size == sizeof(dpc_scene_data));
  CHECK(current.exact_order == 3);
  CHECK(current.material_transmissions == nullptr);
  Guarded<SceneDataV060> sized;
  CHECK(dpc_scene_data_init_sized(reinterpret_cast<dpc_scene_data*>(&sized.old),
                                  sizeof(SceneDataV060)) == DPC_OK);
  CHECK(sized.afterIntact());
  CHECK(sized.old.struct_size == sizeof(SceneDataV060));
  CHECK(sized.old.rays_per_frame == current.rays_per_frame);
  CHECK(sized.old.ambisonic_order == current.ambisonic_order);
  Guarded<SceneDataV060> plain;
  (dpc_scene_data_init)(reinterpret_cast<dpc_scene_data*>(&plain.old));
  CHECK(plain.afterIntact());
  CHECK(std::memcmp(&plain.old, &sized.old, sizeof(SceneDataV060)) == 0);
  Guarded<OptionsV060> options;
  (dpc_engine_options_init)(reinterpret_cast<dpc_engine_options*>(&options.old));
  CHECK(options.afterIntact());
  CHECK(options.old.struct_size == sizeof(OptionsV060));
  CHECK(options.old.rays_per_frame == 0);
  CHECK(dpc_engine_options_init_sized(nullptr, sizeof(dpc_engine_options)) ==
        DPC_ERR_INVALID_ARGUMENT);
}

TEST_CASE("Growth rule: a size that is no known layout is refused, naming both sizes") {
  const size_t current = sizeof(dpc_stats);
  for (const size_t size : {size_t(0), sizeof(size_t), sizeof(StatsV050) + 8, current + 8,
                            size_t(1) << 40}) {
    BoxData box;
    dpc_engine* e = nullptr;
    REQUIRE(dpc_engine_create_from_data(&box.data(), nullptr, &e) == DPC_OK);
    Guarded<dpc_stats> stats;
    stats.old.struct_size = size;
    CHECK(dpc_engine_get_stats(e, &stats.old) == DPC_ERR_VERSION);
    CHECK(messageHas("dpc_stats.struct_size: " + std::to_string(size) + " bytes"));
    // The current layout last, its releases up to this one: "192 (0.9.0)".
    CHECK(messageHas(" " + std::to_string(current) + " ("));
    CHECK(messageHas(DPC_VERSION_STRING ")"));
    CHECK(stats.afterIntact());
    CHECK(stats.bytes[sizeof(size_t)] == kCanary);  // nothing written
    dpc_engine_destroy(e);

    dpc_scene_data d = box.data();
    d.struct_size = size;
    CHECK(dpc_engine_create_from_data(&d, nullptr, &e) == DPC_ERR_VERSION);
    CHECK(e == nullptr);
    CHECK(messageHas("dpc_scene_data.struct_size: " + std::to_string(size) + " bytes"));
    dpc_engine_options o;
    dpc_engine_options_init(&o);
    o.struct_size = size;
    CHECK(dpc_engine_create_from_data(&box.data(), &o, &e) == DPC_ERR_VERSION);
    CHECK(messageHas("dpc_engine_options.struct_size: " + std::to_string(size) + " bytes"));
    Guarded<dpc_scene_data> init;
    CHECK(dpc_scene_data_init_sized(&init.old, size) == DPC_ERR_VERSION);
    CHECK(init.bytes[0] == kCanary);  // nothing written
  }
}

TEST_CASE("Growth rule: DPC_VERSION_COMPATIBLE accepts this major version's libraries not older "
          "than the header") {
  CHECK(DPC_VERSION_COMPATIBLE(dpc_version()));
  CHECK(DPC_VERSION_COMPATIBLE(DPC_MAKE_VERSION(DPC_VERSION_MAJOR, DPC_VERSION_MINOR + 1, 0)));
  CHECK_FALSE(DPC_VERSION_COMPATIBLE(DPC_MAKE_VERSION(DPC_VERSION_MAJOR, DPC_VERSION_MINOR - 1, 0)));
  CHECK_FALSE(DPC_VERSION_COMPATIBLE(DPC_MAKE_VERSION(DPC_VERSION_MAJOR + 1, 0, 0)));
}
