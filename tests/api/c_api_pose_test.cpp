// One pose struct for listeners, sources and moving objects (include/dpc/dpc_poses.h): the
// quaternion turns a listener's ears and a source's pattern as the frame says, checked on the
// direct sound's physics; the setters of 0.2.0 to 0.6.0 give the same result for the same
// pose; a refused pose changes nothing and its message names the field.
#include <catch2/catch.hpp>
#include <cmath>
#include <string>
#include <vector>

#include "dpc/dpc.h"
#include "tests/api/box_data.h"

namespace {

using dpc::test::BoxData;

constexpr float kHalf = 0.70710678f;           // cos 45 degrees
constexpr dpc_pose kFacingPlusX{{0, 0, 0}, {0, 0, 0, 1}};
constexpr double kPi = 3.14159265358979323846;

/// Channel `channel`'s impulse response of source 0 after one frame.
std::vector<float> ir(dpc_engine* e, int channel) {
  size_t n = 0;
  REQUIRE(dpc_engine_copy_impulse_response(e, 0, channel, nullptr, 0, &n, nullptr) == DPC_OK);
  std::vector<float> out(n);
  REQUIRE(dpc_engine_copy_impulse_response(e, 0, channel, out.data(), n, nullptr, nullptr) ==
          DPC_OK);
  return out;
}

double energy(const std::vector<float>& x, size_t samples) {
  double sum = 0.0;
  for (size_t n = 0; n < samples && n < x.size(); ++n) sum += double(x[n]) * x[n];
  return sum;
}

/// Source 0's energy response at 500 Hz in the bin of a direct sound over `metres` (1/m^2).
double directEnergy(dpc_engine* e, double metres) {
  std::vector<float> er(200 * DPC_BANDS);
  double binSeconds = 0.0;
  REQUIRE(dpc_engine_copy_energy_response(e, 0, er.data(), 200, nullptr, &binSeconds, nullptr) ==
          DPC_OK);
  const double c = 331.3 * std::sqrt(1.0 + 20.0 / 273.15);  // the default: dry air at 20 C
  return er[size_t(metres / c / binSeconds) * DPC_BANDS + 3];
}

bool messageHas(const std::string& text) {
  return std::string(dpc_last_error()).find(text) != std::string::npos;
}

}  // namespace

TEST_CASE("Poses: a listener's quaternion turns its ears (stereo direct sound)") {
  BoxData box;
  // 1.2 m away, 45 degrees to the left of a listener at rest (facing +x, left is -z).
  box.sources[0].position[0] = 4.f + 0.8485f;
  box.sources[0].position[2] = 2.f - 0.8485f;
  box.d.output = DPC_OUTPUT_STEREO;
  dpc_engine* e = nullptr;
  REQUIRE(dpc_engine_create_from_data(&box.data(), nullptr, &e) == DPC_OK);
  // The direct sound arrives after 3.5 ms, the first reflections (3.2 m) after 9.4 ms: the
  // first 8 ms at 48 kHz hold the direct sound alone.
  const size_t direct = 384;
  auto leftOverRight = [&] {
    REQUIRE(dpc_engine_step(e) == DPC_OK);
    return energy(ir(e, 0), direct) / energy(ir(e, 1), direct);
  };
  auto place = [&](float qy, float qw) {
    const dpc_pose p{{4.f, 1.5f, 2.f}, {0.f, qy, 0.f, qw}};
    REQUIRE(dpc_engine_place_listener(e, 0, &p) == DPC_OK);
    return leftOverRight();
  };
  // Sine/cosine panning (docs/spatial.md): azimuth a (left positive) gives left/right energy
  // tan^2((a + 90) / 2), 5.83 at 45 degrees left; turned 180 degrees about +y, 1 / 5.83.
  const double law = std::pow(std::tan(67.5 * kPi / 180.0), 2.0);
  CHECK(place(0.f, 1.f) == Approx(law).epsilon(0.01));
  CHECK(place(1.f, 0.f) == Approx(1.0 / law).epsilon(0.01));
  // Turned 45 degrees left (yaw 45 about +y) it faces the source: both ears alike.
  const float s = 0.38268343f, c = 0.92387953f;  // sin, cos 22.5 degrees
  const double facing = place(s, c);
  CHECK(facing == Approx(1.0).epsilon(0.01));
  REQUIRE(dpc_engine_set_listener_pose(e, 0, 4.f, 1.5f, 2.f, 45.f, 0.f) == DPC_OK);
  CHECK(leftOverRight() == Approx(facing).epsilon(1e-4));  // the 0.2.0 setter, the same pose
  dpc_engine_destroy(e);
}

TEST_CASE("Poses: a source's pose moves it and turns its pattern (cardioid direct sound)") {
  BoxData box;
  box.directivities.assign(1, dpc_source_directivity{{0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f,
                                                      0.5f},
                                                     {0.f, 0.f, 0.f, 1.f}});
  dpc_engine* e = nullptr;
  REQUIRE(dpc_engine_create_from_data(&box.data(), nullptr, &e) == DPC_OK);
  // A cardioid, g = (0.5 + 0.5 cos theta)^2 over its mean 1/3: 3 on axis, 0 behind. The
  // listener stands 2 m along +x; at 500 Hz air absorption over 3 m is below 0.01 dB.
  auto direct = [&](const dpc_pose& pose, double metres) {
    REQUIRE(dpc_engine_place_source(e, 0, &pose) == DPC_OK);
    REQUIRE(dpc_engine_step(e) == DPC_OK);
    return directEnergy(e, metres) * 4.0 * kPi * metres * metres;
  };
  CHECK(direct(dpc_pose{{2.f, 1.5f, 2.f}, {0, 0, 0, 1}}, 2.0) == Approx(3.0).epsilon(0.01));
  CHECK(direct(dpc_pose{{2.f, 1.5f, 2.f}, {0, 1, 0, 0}}, 2.0) < 1e-3);  // facing away
  CHECK(direct(dpc_pose{{1.f, 1.5f, 2.f}, {0, 0, 0, 2}}, 3.0) == Approx(3.0).epsilon(0.01));
  // Refused (the rotation), so nothing changes: not even the valid position.
  const dpc_pose bad{{3.f, 1.5f, 2.f}, {0, 0, 0, 0}};
  CHECK(dpc_engine_place_source(e, 0, &bad) == DPC_ERR_INVALID_ARGUMENT);
  CHECK(messageHas("dpc_engine_place_source: pose.rotation is zero or not finite"));
  REQUIRE(dpc_engine_step(e) == DPC_OK);
  CHECK(directEnergy(e, 3.0) * 4.0 * kPi * 9.0 == Approx(3.0).epsilon(0.01));
  dpc_engine_destroy(e);
}

TEST_CASE("Poses: an object's pose equals the 0.2.0 setter's, and the door closes") {
  // Listener "b" in room B hears the talker in room A through the doorway, open at 90 degrees
  // about +y, shut at the rest pose (scenes/generate_two_rooms.py).
  dpc_engine_options o;
  dpc_engine_options_init(&o);
  o.rays_per_frame = 512;
  o.host_inputs_only = 1;
  auto run = [&](bool viaPose, float qy, float qw) {
    dpc_engine* e = nullptr;
    REQUIRE(dpc_engine_create_from_file(DPC_SOURCE_DIR "/scenes/two_rooms.json", &o, &e) ==
            DPC_OK);
    REQUIRE(dpc_engine_select_listener(e, 1) == DPC_OK);
    const dpc_pose door{{6.f, 0.f, 3.5f}, {0.f, qy, 0.f, qw}};
    if (viaPose)
      REQUIRE(dpc_engine_place_object(e, 0, &door) == DPC_OK);
    else
      REQUIRE(dpc_engine_set_object_pose(e, 0, 6.f, 0.f, 3.5f, 0.f, qy, 0.f, qw) == DPC_OK);
    for (int i = 0; i < 3; ++i) REQUIRE(dpc_engine_step(e) == DPC_OK);
    std::vector<float> out = ir(e, 0);
    dpc_engine_destroy(e);
    return out;
  };
  const std::vector<float> open = run(true, kHalf, kHalf);
  CHECK(open == run(false, kHalf, kHalf));
  // Shut: listener "b" hears less.
  CHECK(energy(run(true, 0.f, 1.f), open.size()) < energy(open, open.size()));
}

TEST_CASE("Poses: refused poses name the field") {
  BoxData box;
  dpc_engine* e = nullptr;
  REQUIRE(dpc_engine_create_from_data(&box.data(), nullptr, &e) == DPC_OK);
  dpc_pose far = kFacingPlusX;
  far.position[1] = 2e6f;
  CHECK(dpc_engine_place_listener(e, 0, &far) == DPC_ERR_INVALID_ARGUMENT);
  CHECK(messageHas("dpc_engine_place_listener: pose.position[1]: 2000000 is outside"));
  dpc_pose nan = kFacingPlusX;
  nan.rotation[3] = NAN;
  CHECK(dpc_engine_place_listener(e, 0, &nan) == DPC_ERR_INVALID_ARGUMENT);
  CHECK(messageHas("pose.rotation is zero or not finite"));
  CHECK(dpc_engine_place_listener(e, 1, &kFacingPlusX) == DPC_ERR_INVALID_ARGUMENT);
  CHECK(messageHas("listener: 1 is out of range"));
  CHECK(dpc_engine_place_source(e, 0, nullptr) == DPC_ERR_INVALID_ARGUMENT);
  CHECK(messageHas("dpc_engine_place_source: pose is NULL"));
  CHECK(dpc_engine_place_object(e, 0, &kFacingPlusX) == DPC_ERR_INVALID_ARGUMENT);
  CHECK(messageHas("object: 0 is out of range (0 moving objects)"));
  CHECK(dpc_engine_place_object(nullptr, 0, &kFacingPlusX) == DPC_ERR_INVALID_ARGUMENT);
  CHECK(messageHas("dpc_engine_place_object: engine is NULL"));
  dpc_engine_destroy(e);
}

namespace {

struct Logged {
  std::vector<std::pair<dpc_log_level, std::string>> lines;
  size_t saying(const std::string& text) const {
    size_t n = 0;
    for (const auto& l : lines) n += l.second.find(text) != std::string::npos;
    return n;
  }
};

void keep(dpc_log_level level, const char* message, void* user) {
  static_cast<Logged*>(user)->lines.emplace_back(level, message);
}

}  // namespace

TEST_CASE("Poses: a listener moved out of the room is told it hears nothing, once, and back") {
  // The box is closed and its walls transmit nothing: from outside no direct sound and no path
  // reaches the listener (the physics), while inside the source is in plain view.
  BoxData box;
  dpc_engine* e = nullptr;
  REQUIRE(dpc_engine_create_from_data(&box.data(), nullptr, &e) == DPC_OK);
  Logged logged;
  dpc_set_log_callback(&keep, &logged);
  const std::string silent = "hears none of the 1 sources";
  REQUIRE(dpc_engine_step(e) == DPC_OK);
  CHECK(logged.saying(silent) == 0);
  // Teleported, so that the cache does not carry the paths heard inside for its window.
  REQUIRE(dpc_engine_set_listener_pose(e, 0, 50.f, 1.5f, 2.f, 0.f, 0.f) == DPC_OK);
  REQUIRE(dpc_engine_teleport_listener(e, 0) == DPC_OK);
  // Said once the silence has lasted kSilenceSettleFrames (3) frames, and once only.
  for (int frame = 0; frame < 2; ++frame) REQUIRE(dpc_engine_step(e) == DPC_OK);
  CHECK(logged.saying(silent) == 0);
  for (int frame = 0; frame < 4; ++frame) REQUIRE(dpc_engine_step(e) == DPC_OK);
  CHECK(energy(ir(e, 0), ir(e, 0).size()) == 0.0);
  REQUIRE(logged.saying(silent) == 1);
  CHECK(logged.saying("(50.00, 1.50, 2.00) m") == 1);
  REQUIRE(dpc_engine_set_listener_pose(e, 0, 4.f, 1.5f, 2.f, 0.f, 0.f) == DPC_OK);
  REQUIRE(dpc_engine_teleport_listener(e, 0) == DPC_OK);
  for (int frame = 0; frame < 3; ++frame) REQUIRE(dpc_engine_step(e) == DPC_OK);
  CHECK(energy(ir(e, 0), ir(e, 0).size()) > 0.0);
  CHECK(logged.saying("hears the sources again") == 1);
  CHECK(logged.saying(silent) == 1);
  dpc_set_log_callback(nullptr, nullptr);
  dpc_engine_destroy(e);
}
