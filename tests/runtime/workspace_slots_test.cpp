// WorkspaceSlots (runtime/workspace_slots.h): a slot is held by one job at a time. Threads
// take and give back slots many times over; each slot counts its holders, and a second holder
// at once is a failure (the oracle is the count, not the pool's own bookkeeping).
#include "runtime/workspace_slots.h"

#include <array>
#include <atomic>
#include <catch2/catch.hpp>
#include <thread>
#include <vector>

using namespace dpc;

TEST_CASE("Workspace slots: each held by one job at a time, every one used", "[runtime]") {
  constexpr size_t kThreads = 4, kRounds = 20000;
  WorkspaceSlots slots;
  slots.reset(kThreads);  // as many slots as jobs that run at once
  std::array<std::atomic<int>, kThreads> holders{};
  std::array<std::atomic<uint64_t>, kThreads> uses{};
  std::atomic<uint64_t> overlaps{0};
  std::vector<std::thread> threads;
  for (size_t t = 0; t < kThreads; ++t)
    threads.emplace_back([&] {
      for (size_t r = 0; r < kRounds; ++r) {
        const WorkspaceSlots::Held held(slots);
        if (holders[held.slot()].fetch_add(1) != 0) ++overlaps;
        ++uses[held.slot()];
        holders[held.slot()].fetch_sub(1);
      }
    });
  for (std::thread& t : threads) t.join();
  CHECK(overlaps == 0);
  uint64_t total = 0;
  for (size_t i = 0; i < kThreads; ++i) total += uses[i];
  CHECK(total == kThreads * kRounds);
  // With one slot fewer than the threads, jobs wait for one and still never share it.
  slots.reset(kThreads - 1);
  threads.clear();
  for (size_t t = 0; t < kThreads; ++t)
    threads.emplace_back([&] {
      for (size_t r = 0; r < kRounds / 10; ++r) {
        const WorkspaceSlots::Held held(slots);
        if (held.slot() >= kThreads - 1) ++overlaps;  // a slot the pool does not have
        if (holders[held.slot()].fetch_add(1) != 0) ++overlaps;
        holders[held.slot()].fetch_sub(1);
      }
    });
  for (std::thread& t : threads) t.join();
  CHECK(overlaps == 0);
}
