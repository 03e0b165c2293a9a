// The C API's run-time calls misused as a careless host would: every pose setter, process,
// the read-outs, the getters and the lifetime calls with NULL, non-finite, huge, negative and
// off-by-one arguments, each in a forked child (tests/api/misuse.h).
#include <catch2/catch.hpp>
#include <cfloat>
#include <climits>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "dpc/dpc.h"
#include "tests/api/misuse.h"

using namespace dpc::test;

namespace {

int process(int frames, const std::string& nulled, bool hostInputs = true) {
  return withBox(
      [&](dpc_engine* e) {
        static std::vector<float> l(8192), r(8192), in(8192, 0.1f);
        float* outs[2] = {nulled == "out0" ? nullptr : l.data(),
                          nulled == "out1" ? nullptr : r.data()};
        const float* ins[1] = {nulled == "in0" ? nullptr : in.data()};
        dpc_engine_step(e);
        return dpc_engine_process(e, hostInputs ? ins : nullptr, outs, frames);
      },
      [](dpc_scene_data& d) { d.output = DPC_OUTPUT_STEREO; });
}

/// Every value a coordinate must refuse: non-finite, huge, one step beyond the limit.
const std::vector<std::pair<const char*, float>> kBadCoordinates = {
    {"nan", kNan},   {"inf", kInf},   {"-inf", -kInf},       {"FLT_MAX", FLT_MAX},
    {"1e20", 1e20f}, {"-1e7", -1e7f}, {"1000001", 1000001.f}};

/// The setters of poses: each coordinate with every bad value, then a frame still runs.
std::vector<Misuse> poseCases() {
  std::vector<Misuse> c;
  for (const auto& [what, v] : kBadCoordinates) {
    const float bad = v;
    for (int axis = 0; axis < 3; ++axis) {
      const char* name = axis == 0 ? "x" : axis == 1 ? "y" : "z";
      float p[3] = {2.f, 1.5f, 2.f};
      p[axis] = bad;
      c.push_back({std::string("source ") + name + " = " + what, kBad,
                   [p] {
                     return withBox([&](dpc_engine* e) {
                       return dpc_engine_set_source_position(e, 0, p[0], p[1], p[2]);
                     });
                   },
                   std::string("dpc_engine_set_source_position: ") + name + ": "});
      c.push_back({std::string("listener ") + name + " = " + what, kBad,
                   [p] {
                     return withBox([&](dpc_engine* e) {
                       return dpc_engine_set_listener_pose(e, 0, p[0], p[1], p[2], 0.f, 0.f);
                     });
                   },
                   std::string("dpc_engine_set_listener_pose: ") + name + ": "});
    }
    // Refused, and the next frame traces from the previous, valid position.
    c.push_back({std::string("source x = ") + what + ", then a frame", DPC_OK,
                 [bad] {
                   return withBox([&](dpc_engine* e) {
                     dpc_engine_set_source_position(e, 0, bad, 1.f, 1.f);
                     dpc_engine_set_listener_pose(e, 0, bad, 1.f, 1.f, 0.f, 0.f);
                     return dpc_engine_step(e);
                   });
                 },
                 ""});
  }
  c.push_back({"source at the limit, then a frame", DPC_OK,
               [] {
                 return withBox([](dpc_engine* e) {
                   const dpc_status s = dpc_engine_set_source_position(e, 0, 1e6f, -1e6f, 1e6f);
                   return s != DPC_OK ? s : dpc_engine_step(e);
                 });
               },
               ""});
  return c;
}

/// Indices and angles of the source and listener setters.
std::vector<Misuse> indexAndAngleCases() {
  auto listener = [](int i, float yaw, float pitch) {
    return [=] {
      return withBox([&](dpc_engine* e) {
        return dpc_engine_set_listener_pose(e, i, 1.f, 1.f, 1.f, yaw, pitch);
      });
    };
  };
  auto head = [](int i, float roll) {
    return [=] {
      return withBox([&](dpc_engine* e) {
        return dpc_engine_set_listener_head_pose(e, i, 1.f, 1.f, 1.f, 0.f, 0.f, roll);
      });
    };
  };
  return {
      {"source -1", kBad,
       [] {
         return withBox(
             [](dpc_engine* e) { return dpc_engine_set_source_position(e, -1, 1, 1, 1); });
       },
       "source: -1 is out of range"},
      {"source == count", kBad,
       [] {
         return withBox(
             [](dpc_engine* e) { return dpc_engine_set_source_position(e, 1, 1, 1, 1); });
       },
       "source: 1 is out of range"},
      {"source INT_MIN", kBad,
       [] {
         return withBox(
             [](dpc_engine* e) { return dpc_engine_set_source_position(e, INT_MIN, 1, 1, 1); });
       },
       "out of range"},
      {"source, NULL engine", kBad,
       [] { return dpc_engine_set_source_position(nullptr, 0, 1, 1, 1); }, "engine is NULL"},
      {"listener -1", kBad, listener(-1, 0, 0), "listener: -1 is out of range"},
      {"listener == count", kBad, listener(1, 0, 0), "listener: 1 is out of range"},
      {"listener, NULL engine", kBad,
       [] { return dpc_engine_set_listener_pose(nullptr, 0, 1, 1, 1, 0, 0); }, "engine is NULL"},
      {"yaw 3600", DPC_OK, listener(0, 3600.f, 0), ""},
      {"yaw 3601", kBad, listener(0, 3601.f, 0), "yaw_degrees: 3601 is outside [-3600, 3600]"},
      {"yaw nan", kBad, listener(0, kNan, 0), "yaw_degrees: nan"},
      {"pitch -90", DPC_OK, listener(0, 0, -90.f), ""},
      {"pitch 90.01", kBad, listener(0, 0, 90.01f), "pitch_degrees: 90.01 is outside"},
      {"pitch -inf", kBad, listener(0, 0, -kInf), "pitch_degrees: -inf"},
      {"roll -180", DPC_OK, head(0, -180.f), ""},
      {"roll 180.01", kBad, head(0, 180.01f), "roll_degrees: 180.01 is outside [-180, 180]"},
      {"roll nan", kBad, head(0, kNan), "roll_degrees: nan"},
      {"head pose, listener == count", kBad, head(1, 0.f), "listener: 1 is out of range"},
      {"head pose, NULL engine", kBad,
       [] { return dpc_engine_set_listener_head_pose(nullptr, 0, 1, 1, 1, 0, 0, 0); },
       "engine is NULL"},
  };
}

/// Selection, object indices and quaternions.
std::vector<Misuse> selectAndQuaternionCases() {
  return {
      {"select -1", kBad,
       [] { return withBox([](dpc_engine* e) { return dpc_engine_select_listener(e, -1); }); },
       "listener: -1 is out of range"},
      {"select == count", kBad,
       [] { return withBox([](dpc_engine* e) { return dpc_engine_select_listener(e, 1); }); },
       "listener: 1 is out of range"},
      {"select, NULL engine", kBad, [] { return dpc_engine_select_listener(nullptr, 0); },
       "engine is NULL"},
      {"object 0 of none", kBad,
       [] {
         return withBox(
             [](dpc_engine* e) { return dpc_engine_set_object_pose(e, 0, 0, 0, 0, 0, 0, 0, 1); });
       },
       "object: 0 is out of range (0 moving objects)"},
      {"object, NULL engine", kBad,
       [] { return dpc_engine_set_object_pose(nullptr, 0, 0, 0, 0, 0, 0, 0, 1); },
       "engine is NULL"},
      {"quaternion, NULL outputs", kBad,
       [] {
         float yaw = 0;
         return dpc_yaw_pitch_from_quaternion(0, 0, 0, 1, &yaw, nullptr);
       },
       "NULL"},
      {"quaternion zero", kBad,
       [] {
         float yaw = 0, pitch = 0;
         return dpc_yaw_pitch_from_quaternion(0, 0, 0, 0, &yaw, &pitch);
       },
       "q is zero"},
      {"quaternion nan", kBad,
       [] {
         float yaw = 0, pitch = 0;
         return dpc_yaw_pitch_from_quaternion(kNan, 0, 0, 1, &yaw, &pitch);
       },
       "not finite"},
      {"quaternion FLT_MAX is a rotation", DPC_OK,
       [] {
         float yaw = 0, pitch = 0;
         const dpc_status s = dpc_yaw_pitch_from_quaternion(0, FLT_MAX, 0, FLT_MAX, &yaw, &pitch);
         return s == DPC_OK && std::abs(yaw - 90.f) < 1e-3f ? s : kWrongMessage;
       },
       ""},
  };
}

}  // namespace

TEST_CASE("C API misuse: pose setters refuse coordinates beyond the scene's limit", "[misuse]") {
  runAll(poseCases());
}

TEST_CASE("C API misuse: pose setters refuse bad indices, angles and quaternions", "[misuse]") {
  runAll(indexAndAngleCases());
  runAll(selectAndQuaternionCases());
}

namespace {

/// Calls f with an engine of scenes/two_rooms.json (a moving object), host inputs only.
int withObjectScene(const std::function<int(dpc_engine*)>& f) {
  dpc_engine_options o;
  dpc_engine_options_init(&o);
  o.host_inputs_only = 1;
  dpc_engine* e = nullptr;
  if (dpc_engine_create_from_file(DPC_SOURCE_DIR "/scenes/two_rooms.json", &o, &e) != DPC_OK ||
      dpc_engine_object_count(e) < 1)
    return kNoEngine;
  const int r = f(e);
  dpc_engine_destroy(e);
  return r;
}

std::vector<Misuse> objectCases() {
  auto pose = [](int object, float x, float qx, float qw) {
    return [=] {
      return withObjectScene([&](dpc_engine* e) {
        const int i = object < 0 ? object : object + dpc_engine_object_count(e) - 1;
        const dpc_status s = dpc_engine_set_object_pose(e, i, x, 0, 0, qx, 0, 0, qw);
        return s != DPC_OK ? s : dpc_engine_step(e);
      });
    };
  };
  return {
      {"last object at the limit, then a frame", DPC_OK, pose(0, 1e6f, 0, 1), ""},
      {"object == count", kBad, pose(1, 0, 0, 1), "object: "},
      {"object -1", kBad, pose(-1, 0, 0, 1), "object: -1 is out of range"},
      {"object x 1e20", kBad, pose(0, 1e20f, 0, 1), "x: 1e+20 is outside"},
      {"object x nan", kBad, pose(0, kNan, 0, 1), "x: nan is outside"},
      {"object q zero", kBad, pose(0, 0, 0, 0), "q is zero or not finite"},
      {"object q inf", kBad, pose(0, 0, kInf, 1), "q is zero or not finite"},
      {"object q 1e30 is a rotation", DPC_OK, pose(0, 0, 1e30f, 1e30f), ""},
      // As dpc_yaw_pitch_roll_from_quaternion reads it: any finite non-zero length.
      {"object q 1e-20 is a rotation", DPC_OK, pose(0, 0, 1e-20f, 1e-20f), ""},
  };
}

/// dpc_engine_process's buffers and frame counts.
std::vector<Misuse> processCases() {
  return {
      {"process 64", DPC_OK, [] { return process(64, ""); }, ""},
      {"process 8192", DPC_OK, [] { return process(8192, ""); }, ""},
      {"process 1, scene signals", DPC_OK, [] { return process(1, "", false); }, ""},
      {"process 0", kBad, [] { return process(0, ""); }, ""},
      {"process -1", kBad, [] { return process(-1, ""); }, ""},
      {"process 8193", kBad, [] { return process(8193, ""); }, ""},
      {"process INT_MAX", kBad, [] { return process(INT_MAX, ""); }, ""},
      {"process INT_MIN", kBad, [] { return process(INT_MIN, ""); }, ""},
      {"process outputs[0] NULL", kBad, [] { return process(64, "out0"); }, ""},
      {"process outputs[1] NULL", kBad, [] { return process(64, "out1"); }, ""},
      {"process inputs[0] NULL", kBad, [] { return process(64, "in0"); }, ""},
      {"process outputs NULL", kBad,
       [] {
         return withBox([](dpc_engine* e) { return dpc_engine_process(e, nullptr, nullptr, 64); });
       },
       ""},
      {"process NULL engine", kBad,
       [] {
         float b[64];
         float* outs[2] = {b, b};
         return dpc_engine_process(nullptr, nullptr, outs, 64);
       },
       ""},
  };
}

/// Impulse-response read-outs: indices, NULL buffers, before the first frame.
std::vector<Misuse> impulseResponseCases() {
  auto ir = [](int source, int channel, bool nullOut, bool step) {
    return [=] {
      return withBox([&](dpc_engine* e) {
        if (step) dpc_engine_step(e);
        float out[16];
        size_t length = 0;
        return dpc_engine_copy_impulse_response(e, source, channel, nullOut ? nullptr : out, 16,
                                                &length, nullptr);
      });
    };
  };
  return {
      {"IR before a frame", DPC_ERR_STATE, ir(0, 0, false, false), "no propagation frame"},
      {"IR", DPC_OK, ir(0, 0, false, true), ""},
      {"IR source -1", kBad, ir(-1, 0, false, true),
       "dpc_engine_copy_impulse_response: source: -1 is out of range"},
      {"IR source == count", kBad, ir(1, 0, false, true),
       "dpc_engine_copy_impulse_response: source: 1 is out of range"},
      {"IR channel == channels", kBad, ir(0, 1, false, true),
       "dpc_engine_copy_impulse_response: channel: 1 is out of range"},
      {"IR channel -1", kBad, ir(0, -1, false, true),
       "dpc_engine_copy_impulse_response: channel: -1 is out of range"},
      {"IR NULL out, capacity 16", kBad, ir(0, 0, true, true),
       "dpc_engine_copy_impulse_response: out is NULL"},
      {"IR NULL engine", kBad,
       [] { return dpc_engine_copy_impulse_response(nullptr, 0, 0, nullptr, 0, nullptr, nullptr); },
       "dpc_engine_copy_impulse_response: engine is NULL"},
  };
}

/// Energy-response read-outs: indices, NULL buffers, before the first frame.
std::vector<Misuse> energyResponseCases() {
  auto er = [](int source, bool nullOut, bool step) {
    return [=] {
      return withBox([&](dpc_engine* e) {
        if (step) dpc_engine_step(e);
        float out[16 * DPC_BANDS];
        return dpc_engine_copy_energy_response(e, source, nullOut ? nullptr : out, 16, nullptr,
                                               nullptr, nullptr);
      });
    };
  };
  return {
      {"ER", DPC_OK, er(0, false, true), ""},
      {"ER source == count", kBad, er(1, false, true),
       "dpc_engine_copy_energy_response: source: 1 is out of range"},
      {"ER source -1", kBad, er(-1, false, true),
       "dpc_engine_copy_energy_response: source: -1 is out of range"},
      {"ER NULL out, capacity 16", kBad, er(0, true, true),
       "dpc_engine_copy_energy_response: out is NULL"},
      {"ER before a frame", DPC_ERR_STATE, er(0, false, false), "no propagation frame"},
  };
}

/// Lifetime, getters and statistics with NULL and wrong sizes.
std::vector<Misuse> lifetimeCases() {
  return {
      {"NULL engine getters are 0", 0,
       [] {
         return dpc_engine_sample_rate(nullptr) + dpc_engine_block_size(nullptr) +
                dpc_engine_output_channels(nullptr) + dpc_engine_source_count(nullptr) +
                dpc_engine_object_count(nullptr) + dpc_engine_latency_frames(nullptr) +
                dpc_engine_listener_count(nullptr) + dpc_engine_selected_listener(nullptr);
       },
       ""},
      {"NULL init, destroy, log callback", 0,
       [] {
         dpc_engine_options_init(nullptr);
         dpc_scene_data_init(nullptr);
         dpc_engine_destroy(nullptr);
         dpc_set_log_callback(nullptr, nullptr);
         return 0;
       },
       ""},
      {"start NULL", kBad, [] { return dpc_engine_start(nullptr); }, "engine is NULL"},
      {"stop NULL", kBad, [] { return dpc_engine_stop(nullptr); }, "engine is NULL"},
      {"step NULL", kBad, [] { return dpc_engine_step(nullptr); }, "engine is NULL"},
      {"step while running", DPC_ERR_STATE,
       [] {
         return withBox([](dpc_engine* e) {
           dpc_engine_start(e);
           dpc_engine_start(e);
           return dpc_engine_step(e);
         });
       },
       "running"},
      {"stop twice, destroy", DPC_OK,
       [] {
         return withBox([](dpc_engine* e) {
           dpc_engine_stop(e);
           return dpc_engine_stop(e);
         });
       },
       ""},
      {"stats NULL", kBad, [] { return dpc_engine_get_stats(nullptr, nullptr); }, "NULL"},
      {"stats size 0", DPC_ERR_VERSION,
       [] {
         return withBox([](dpc_engine* e) {
           dpc_stats s{};
           return dpc_engine_get_stats(e, &s);
         });
       },
       "dpc_stats.struct_size"},
      {"stats size + 1", DPC_ERR_VERSION,
       [] {
         return withBox([](dpc_engine* e) {
           dpc_stats s{};
           s.struct_size = sizeof s + 1;
           return dpc_engine_get_stats(e, &s);
         });
       },
       "dpc_stats.struct_size"},
  };
}

}  // namespace

TEST_CASE("C API misuse: object poses", "[misuse]") {
  runAll(objectCases());
}

TEST_CASE("C API misuse: process with bad buffers and frame counts", "[misuse]") {
  runAll(processCases());
}

TEST_CASE("C API misuse: read-outs", "[misuse]") {
  runAll(impulseResponseCases());
  runAll(energyResponseCases());
}

TEST_CASE("C API misuse: lifetime, getters and statistics", "[misuse]") {
  runAll(lifetimeCases());
}
