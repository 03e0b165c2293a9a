// dpc_engine_destroy of the last engine joins TBB's worker threads (api/scheduler_lease.h), so
// that a host (an LV2 plugin's) may unload libdpc afterwards with no thread of dpc left: the
// process has as many threads after the last destroy as before the first create. Counted
// through /proc/self/task (Linux), an instrument outside dpc.
#include <atomic>
#include <catch2/catch.hpp>
#include <chrono>
#include <set>
#include <thread>
#include <vector>

#include "dpc/dpc.h"
#include "testing/thread_count.h"
#include "tests/api/box_data.h"

namespace {

/// An engine of the box, created, traced (TBB's workers share the trace) and started.
dpc_engine* tracedEngine() {
  dpc::test::BoxData box;
  dpc_engine_options o;
  dpc_engine_options_init(&o);
  o.host_inputs_only = 1;
  dpc_engine* e = nullptr;
  REQUIRE(dpc_engine_create_from_data(&box.data(), &o, &e) == DPC_OK);
  REQUIRE(dpc_engine_step(e) == DPC_OK);
  REQUIRE(dpc_engine_start(e) == DPC_OK);
  return e;
}

}  // namespace

TEST_CASE("C API: no thread of dpc is left after the last engine is destroyed") {
  const int before = dpc::test::threadCount();
  dpc_engine* a = tracedEngine();
  // A second engine built and traced on another thread, as a plugin's loader does.
  dpc_engine* b = nullptr;
  std::thread([&b] { b = tracedEngine(); }).join();
  CHECK(dpc::test::threadCount() > before);  // two propagation threads, and TBB's workers
  dpc_engine_destroy(a);
  CHECK(dpc::test::threadCount() > before);  // b still runs
  dpc_engine_destroy(b);
  CHECK(dpc::test::threadCountSettled(before) == before);
  INFO("threads: " << dpc::test::threadNames());
  // dpc works as before afterwards: TBB starts its workers again on demand.
  dpc_engine* c = tracedEngine();
  dpc_engine_destroy(c);
  CHECK(dpc::test::threadCountSettled(before) == before);
}

// The propagation thread skips a frame's copy for a reader that holds the snapshot, but not
// two in a row: a reader that copies without pause still sees at least every other frame.
// Before, such a reader held off every copy and read frame 1 while 41 frames ran.
TEST_CASE("C API: a reader copying without pause still sees new frames") {
  dpc::test::BoxData box;
  dpc_engine_options o;
  dpc_engine_options_init(&o);
  o.host_inputs_only = 1;
  o.rays_per_frame = 256;
  dpc_engine* e = nullptr;
  REQUIRE(dpc_engine_create_from_data(&box.data(), &o, &e) == DPC_OK);
  size_t length = 0;
  REQUIRE(dpc_engine_step(e) == DPC_OK);
  REQUIRE(dpc_engine_copy_impulse_response(e, 0, 0, nullptr, 0, &length, nullptr) == DPC_OK);
  std::atomic<bool> run{true};
  std::set<uint64_t> seen;  // frames the reader's copies came from while the engine ran
  std::thread reader([&] {
    std::vector<float> ir(length);
    while (run.load()) {
      uint64_t frame = 0;
      if (dpc_engine_copy_impulse_response(e, 0, 0, ir.data(), ir.size(), nullptr, &frame) ==
          DPC_OK)
        seen.insert(frame);
    }
  });
  REQUIRE(dpc_engine_start(e) == DPC_OK);
  dpc_stats st{};
  st.struct_size = sizeof st;
  for (int i = 0; i < 400 && st.frames < 24; ++i) {  // at most 20 s
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    REQUIRE(dpc_engine_get_stats(e, &st) == DPC_OK);
  }
  run = false;
  reader.join();
  dpc_engine_stop(e);
  dpc_engine_destroy(e);
  REQUIRE(st.frames >= 24);
  // Every other frame is stored; half of those again allows for a reader descheduled on a
  // loaded machine. Before: 1 distinct frame.
  INFO("frames " << st.frames << ", distinct frames read " << seen.size());
  CHECK(seen.size() >= st.frames / 4);
}
