// The harness of the C API misuse suites (c_api_misuse_test.cpp, c_api_create_misuse_test.cpp):
// each call runs in a forked child, so that a crash or a hang (an alarm ends it) fails its case
// instead of the suite; the child exits with the call's dpc_status, checked against the
// documented one, or with kWrongMessage when dpc_last_error() does not name what was wrong.
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include "dpc/dpc.h"
#include "tests/api/box_data.h"

namespace dpc::test {

inline constexpr int kWrongMessage =
    100;                               ///< the status was right, the message did not name the fault
inline constexpr int kNoEngine = 101;  ///< the valid engine a case starts from could not be built
inline constexpr int kException = 102;  ///< an exception crossed the C API
inline constexpr unsigned kHangSeconds = 60;

struct Misuse {
  std::string name;
  int expected;            ///< dpc_status, or a count the function returns
  std::function<int()> f;  ///< runs in the child
  std::string messageHas;  ///< "" or a text dpc_last_error() must contain after the call
};

/// Runs m.f in a forked child; its exit status, or 200 + the signal that killed it.
inline int runInChild(const Misuse& m) {
  std::fflush(nullptr);
  const pid_t child = ::fork();
  if (child == 0) {
    ::alarm(kHangSeconds);
    int code = kException;
    try {
      code = m.f();
      if (!m.messageHas.empty() &&
          std::string(dpc_last_error()).find(m.messageHas) == std::string::npos) {
        std::fprintf(stderr, "%s: message \"%s\"\n", m.name.c_str(), dpc_last_error());
        code = kWrongMessage;
      }
    } catch (...) {
    }
    ::_exit(code & 255);
  }
  int status = 0;
  if (child < 0 || ::waitpid(child, &status, 0) != child) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : 200 + WTERMSIG(status);
}

/// Calls f with an engine built from the box (the data changed by `edit` first).
inline int withBox(const std::function<int(dpc_engine*)>& f,
                   const std::function<void(dpc_scene_data&)>& edit = {}) {
  BoxData box;
  dpc_scene_data d = box.data();
  if (edit) edit(d);
  dpc_engine* e = nullptr;
  if (dpc_engine_create_from_data(&d, nullptr, &e) != DPC_OK) return kNoEngine;
  const int r = f(e);
  dpc_engine_destroy(e);
  return r;
}

/// The status of creating an engine from the box changed by `edit`.
inline int createBox(const std::function<void(BoxData&, dpc_scene_data&)>& edit) {
  BoxData box;
  dpc_scene_data d = box.data();
  edit(box, d);
  dpc_engine* e = reinterpret_cast<dpc_engine*>(&box);  // must come back NULL on failure
  const dpc_status s = dpc_engine_create_from_data(&d, nullptr, &e);
  if (s != DPC_OK && e != nullptr) return kWrongMessage;
  dpc_engine_destroy(e);
  return s;
}

/// The status of creating the shoebox scene with options changed by `edit`.
inline int createWithOptions(const std::function<void(dpc_engine_options&)>& edit) {
  dpc_engine_options o;
  dpc_engine_options_init(&o);
  o.host_inputs_only = 1;
  edit(o);
  dpc_engine* e = nullptr;
  const dpc_status s = dpc_engine_create_from_file(DPC_SOURCE_DIR "/scenes/shoebox.json", &o, &e);
  dpc_engine_destroy(e);
  return s;
}

/// dpc_engine_process on the box with `frames` frames, buffers of 8192 frames, and the
/// output or input pointer `nulled` ("out0", "out1", "in0", "") set to NULL.
inline constexpr float kNan = NAN;
inline constexpr float kInf = INFINITY;
inline constexpr int kBad = DPC_ERR_INVALID_ARGUMENT;
inline constexpr int kInput = DPC_ERR_INPUT;

/// Checks every case of a group: each child exits with the expected code (no crash, no hang).
inline void runAll(const std::vector<Misuse>& cases) {
  for (const Misuse& m : cases) {
    INFO(m.name);
    CHECK(runInChild(m) == m.expected);
  }
}

}  // namespace dpc::test
