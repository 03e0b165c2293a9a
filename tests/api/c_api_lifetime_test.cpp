// The C API's lifetime rule (include/dpc/dpc.h, "Lifetime"): dpc_engine_destroy must not overlap
// another call on the engine; when a host breaks that, destroy waits for the calls already
// inside the engine (a copy, a process call) instead of freeing it under them, refuses the
// calls that arrive meanwhile or later with DPC_ERR_STATE, and logs the misuse.
#include <atomic>
#include <catch2/catch.hpp>
#include <string>
#include <thread>
#include <vector>

#include "dpc/dpc.h"
#include "tests/api/box_data.h"

namespace {

using dpc::test::BoxData;

/// Warnings the library logged (dpc_set_log_callback), installed for one test's scope.
struct Warnings {
  std::vector<std::string> lines;
  Warnings() { dpc_set_log_callback(&Warnings::collect, this); }
  ~Warnings() { dpc_set_log_callback(nullptr, nullptr); }
  static void collect(dpc_log_level level, const char* message, void* user) {
    if (level == DPC_LOG_WARNING) static_cast<Warnings*>(user)->lines.emplace_back(message);
  }
  int count(const std::string& text) const {
    int n = 0;
    for (const std::string& line : lines) n += line.find(text) != std::string::npos;
    return n;
  }
};

/// What a host thread calling `call` in a loop until it is refused saw.
struct Loop {
  std::atomic<int> calls{0};
  dpc_status last = DPC_OK;
  std::string message;
};

template <class Call>
std::thread loopUntilRefused(Loop& loop, Call call) {
  return std::thread([&loop, call] {
    dpc_status s;
    while ((s = call()) == DPC_OK) loop.calls.fetch_add(1);
    loop.last = s;
    loop.message = dpc_last_error();
  });
}

constexpr const char* kWaited = "still inside the engine; waited for them";

}  // namespace

TEST_CASE("Lifetime: destroy racing a copy loop and a process loop waits, then refuses them") {
  Warnings warnings;
  constexpr int kTrials = 10;
  for (int trial = 0; trial < kTrials; ++trial) {
    BoxData box;
    dpc_engine* e = nullptr;
    REQUIRE(dpc_engine_create_from_data(&box.data(), nullptr, &e) == DPC_OK);
    REQUIRE(dpc_engine_step(e) == DPC_OK);
    const int block = dpc_engine_block_size(e);
    Loop copies, blocks;
    std::thread copier = loopUntilRefused(copies, [e] {
      thread_local std::vector<float> ir(size_t(1) << 17);
      return dpc_engine_copy_impulse_response(e, 0, 0, ir.data(), ir.size(), nullptr, nullptr);
    });
    std::thread audio = loopUntilRefused(blocks, [e, block] {
      thread_local std::vector<float> out(static_cast<size_t>(block));
      float* outputs[1] = {out.data()};
      return dpc_engine_process(e, nullptr, outputs, block);
    });
    while (copies.calls.load() < 20 || blocks.calls.load() < 20) std::this_thread::yield();
    dpc_engine_destroy(e);  // the misuse: both threads are still calling
    copier.join();
    audio.join();
    CHECK(copies.last == DPC_ERR_STATE);
    CHECK(copies.message.find("the engine is being destroyed") != std::string::npos);
    CHECK(blocks.last == DPC_ERR_STATE);
    // A late call on the destroyed handle is refused, not a read of freed memory.
    CHECK(dpc_engine_sample_rate(e) == 0);
    CHECK(dpc_engine_step(e) == DPC_ERR_STATE);
  }
  // Each copy spends its time inside the engine (192 kB copied), so destroy found one there in
  // nearly every trial; at least one must have been waited for and reported.
  CHECK(warnings.count(kWaited) >= 1);
  CHECK(warnings.count(kWaited) <= kTrials);
}

TEST_CASE("Lifetime: a destroyed handle stays closed and the next engines get other handles") {
  BoxData box;
  dpc_engine* old = nullptr;
  REQUIRE(dpc_engine_create_from_data(&box.data(), nullptr, &old) == DPC_OK);
  dpc_engine_destroy(old);
  // Freed at once, its memory would be the allocator's first choice for the next engine, and
  // a late call on the old handle would act on that engine.
  std::vector<dpc_engine*> next(3, nullptr);
  for (dpc_engine*& e : next) {
    REQUIRE(dpc_engine_create_from_data(&box.data(), nullptr, &e) == DPC_OK);
    CHECK(e != old);
  }
  CHECK(dpc_engine_step(old) == DPC_ERR_STATE);
  CHECK(std::string(dpc_last_error()) == "dpc_engine_step: the engine is being destroyed");
  for (dpc_engine* e : next) dpc_engine_destroy(e);
}

TEST_CASE("Lifetime: a destroy that overlaps nothing reports nothing") {
  Warnings warnings;
  BoxData box;
  dpc_engine* e = nullptr;
  REQUIRE(dpc_engine_create_from_data(&box.data(), nullptr, &e) == DPC_OK);
  REQUIRE(dpc_engine_step(e) == DPC_OK);
  std::thread reader([e] {
    size_t n = 0;
    CHECK(dpc_engine_copy_impulse_response(e, 0, 0, nullptr, 0, &n, nullptr) == DPC_OK);
  });
  reader.join();  // the rule kept: the reader is done before destroy
  dpc_engine_destroy(e);
  CHECK(warnings.count(kWaited) == 0);
}
