// dpc_engine_destroy of the last engine joins TBB's worker threads (api/scheduler_lease.h), so
// that a host (an LV2 plugin's) may unload libdpc afterwards with no thread of dpc left: the
// process has as many threads after the last destroy as before the first create. Counted
// through /proc/self/task (Linux), an instrument outside dpc.
#include <catch2/catch.hpp>
#include <thread>

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
