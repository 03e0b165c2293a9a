// libFuzzer target: dpc_engine_create_from_data on arbitrary scene data, then one propagation
// frame and the pose setters. The input bytes are decoded into a dpc_scene_data (counts,
// indices that may be one past the end, floats that are either small numbers or raw bit
// patterns: NaN, infinities, huge and denormal values), with host inputs only. A refusal must
// be a dpc_status with a message; a crash, a hang, a sanitizer report or an exception escaping
// the API is a finding. Fields whose in-range values only cost time or memory (ir_length,
// rays_per_frame, max_order, the sample rate, counts, the order of a binaural decoding) are
// capped when in range, so that each input stays cheap; out-of-range raw values pass unchanged.
// Corpus: fuzz/corpus/c_api (fuzz/make_c_api_seeds.py); DPC_FUZZ_VERBOSE=1 prints each input's
// outcome (fuzz/fuzz_report.h).
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "dpc/dpc.h"
#include "fuzz/fuzz_report.h"

namespace {

/// Reads the input front to back; zeros once it is exhausted.
class Bytes {
 public:
  Bytes(const uint8_t* data, size_t size) : data_(data), size_(size) {}
  uint8_t u8() { return at_ < size_ ? data_[at_++] : 0; }
  uint32_t u32() {
    uint32_t v = 0;
    for (int i = 0; i < 4; ++i) v |= uint32_t(u8()) << (8 * i);
    return v;
  }
  /// A small number (a signed byte / 4) or, when the selector's low bit is set, raw bits.
  float f32() {
    if (!(u8() & 1)) return float(int8_t(u8())) / 4.f;
    const uint32_t bits = u32();
    float f;
    std::memcpy(&f, &bits, sizeof f);
    return f;
  }
  /// As f32, but an in-range value above `cap` becomes `cap` (work, not a bug).
  float capped(float cap) {
    const float v = f32();
    return v > cap && v <= 1e30f ? cap : v;
  }
  /// A raw int; one in (cap, limit] (valid, only costly) becomes cap.
  int cappedInt(int cap, int limit) {
    const int v = int(u32());
    return v > cap && v <= limit ? cap : v;
  }
  /// A count: usually in [0, n]; rarely an edge value: -1, INT_MIN, or (when limit > 0) one
  /// beyond `limit` or INT_MAX, which the API must refuse before reading the array. The
  /// arrays themselves hold n entries: a count the API accepts never exceeds them.
  int count(int n, int limit) {
    const uint8_t s = u8();
    if (s != 255) return int(s % (n + 1));
    const int edges[4] = {-1, INT_MIN, limit + 1, INT_MAX};
    return edges[u8() % (limit > 0 ? 4 : 2)];
  }

 private:
  const uint8_t* data_;
  size_t size_;
  size_t at_ = 0;
};

/// The arrays a dpc_scene_data points to.
struct Arrays {
  std::vector<float> vertices;
  std::vector<uint32_t> indices, materialOf;
  std::vector<dpc_material> materials;
  std::vector<dpc_source> sources;
  std::vector<dpc_listener> listeners;
};

void decodeMesh(Bytes& b, Arrays& a, dpc_scene_data& d) {
  const uint32_t vertices = b.u8() % 48, triangles = b.u8() % 48;
  for (uint32_t i = 0; i < 3 * vertices; ++i) a.vertices.push_back(b.f32());
  for (uint32_t i = 0; i < 3 * triangles; ++i) a.indices.push_back(b.u8() % (vertices + 2));
  const int materials = b.count(3, 0);  // no limit to be beyond: the caller's count is trusted
  for (uint32_t i = 0; i < triangles; ++i) a.materialOf.push_back(b.u8() % 5);
  for (int m = 0; m < 4; ++m) {
    dpc_material mat{nullptr, {}, b.f32()};
    for (float& x : mat.absorption) x = b.f32();
    a.materials.push_back(mat);
  }
  d.mesh = dpc_mesh{a.vertices.data(), vertices, a.indices.data(), triangles, a.materialOf.data()};
  d.materials = a.materials.data();
  d.material_count = materials;
}

void decodeEntities(Bytes& b, Arrays& a, dpc_scene_data& d) {
  d.source_count = b.count(3, 256);
  for (int s = 0; s < 4; ++s)
    a.sources.push_back(dpc_source{{b.f32(), b.f32(), b.f32()}, b.f32(), nullptr, 0, 0});
  d.sources = a.sources.data();
  for (float& x : d.listener_position) x = b.f32();
  d.listener_radius = b.f32();
  d.listener_yaw_degrees = b.f32();
  d.listener_pitch_degrees = b.f32();
  d.listener_roll_degrees = b.f32();
  d.additional_listener_count = b.count(2, 63);
  for (int l = 0; l < 3; ++l)
    a.listeners.push_back(
        dpc_listener{{b.f32(), b.f32(), b.f32()}, b.f32(), b.f32(), b.f32(), b.f32()});
  d.additional_listeners = (b.u8() & 1) ? nullptr : a.listeners.data();
}

void decodeSettings(Bytes& b, dpc_scene_data& d) {
  d.rays_per_frame = b.u8() == 255 ? b.cappedInt(64, 100000000) : int(b.u8() % 65);
  d.max_order = b.u8() == 255 ? b.cappedInt(16, 10000) : int(b.u8() % 17);
  d.patch_size = b.f32();
  d.cache_tau = b.f32();
  d.frame_rate = b.f32();
  d.ir_length = b.capped(0.25f);
  d.seed = b.u32();
  d.speed_of_sound = b.f32();
  d.temperature = b.f32();
  d.humidity = b.f32();
  d.air_absorption = b.u8() & 1;
  d.diffraction = b.u8() & 1;
  const uint8_t rate = b.u8();
  d.sample_rate = rate == 255 ? int(b.u32()) : (rate & 1 ? 16000 : 48000);
  d.block_size = b.u8() == 255 ? int(b.u32()) : 256;
  d.output = dpc_output_format(b.u8() % 7);  // SCENE (refused in data) .. AMBISONIC_BINAURAL
  d.ambisonic_order = int(b.u8() % 9);       // 0 and 8 refused
  // Decoded binaurally, orders 4-7 are valid but fit MagLS filters per order at creation
  // (15-35 s for order 7 under the fuzz build's sanitizers and coverage): capped at 3.
  if (d.output == DPC_OUTPUT_AMBISONIC_BINAURAL && d.ambisonic_order > 3 && d.ambisonic_order < 8)
    d.ambisonic_order = 3;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  Bytes b(data, size);
  Arrays a;
  dpc_scene_data d;
  dpc_scene_data_init(&d);
  decodeMesh(b, a, d);
  decodeEntities(b, a, d);
  decodeSettings(b, d);
  dpc_engine_options o;
  dpc_engine_options_init(&o);
  o.host_inputs_only = 1;
  dpc_engine* e = nullptr;
  if (dpc_engine_create_from_data(&d, &o, &e) != DPC_OK) {
    // A refusal: no engine, and a message.
    if (e != nullptr || dpc_last_error()[0] == '\0') std::abort();
    dpc::fuzz::refused(dpc_last_error());
    return 0;
  }
  dpc_engine_set_source_position(e, 0, b.f32(), b.f32(), b.f32());
  dpc_engine_set_listener_pose(e, 0, b.f32(), b.f32(), b.f32(), b.f32(), b.f32());
  if (dpc_engine_step(e) != DPC_OK) std::abort();
  dpc::fuzz::accepted("engine built and stepped");
  dpc_engine_destroy(e);
  return 0;
}
