// FixedRing (common/fixed_ring.h): FIFO order, fixed capacity, refused pushes counted, and an
// ordered hand-over between two threads.
#include "common/fixed_ring.h"

#include <catch2/catch.hpp>
#include <thread>
#include <vector>

using namespace dpc;

TEST_CASE("FixedRing: FIFO order across wrap-around, full ring refuses and counts", "[ring]") {
  FixedRing<int> ring(3);
  CHECK(ring.capacity() == 3);
  CHECK(ring.empty());
  int out = 0;
  CHECK_FALSE(ring.tryPop(out));
  for (int round = 0; round < 5; ++round) {  // indices wrap several times
    CHECK(ring.tryPush(3 * round));
    CHECK(ring.tryPush(3 * round + 1));
    CHECK(ring.tryPush(3 * round + 2));
    CHECK(ring.size() == 3);
    CHECK_FALSE(ring.tryPush(-1));
    CHECK(ring.overflows() == uint64_t(round + 1));
    for (int i = 0; i < 3; ++i) {
      REQUIRE(ring.tryPop(out));
      CHECK(out == 3 * round + i);
    }
    CHECK(ring.empty());
  }
}

TEST_CASE("FixedRing: bulk push takes what fits and counts the rest", "[ring]") {
  FixedRing<float> ring(5);
  const float a[4] = {1, 2, 3, 4};
  CHECK(ring.pushBulk(a, 4) == 4);
  CHECK(ring.pushBulk(a, 4) == 1);
  CHECK(ring.overflows() == 3);
  float b[8] = {};
  CHECK(ring.popBulk(b, 8) == 5);
  CHECK(b[0] == 1.f);
  CHECK(b[3] == 4.f);
  CHECK(b[4] == 1.f);
  CHECK(ring.popBulk(b, 8) == 0);
}

TEST_CASE("FixedRing: one producer and one consumer thread keep every element in order",
          "[ring][threads]") {
  FixedRing<uint32_t> ring(7);
  constexpr uint32_t kCount = 200000;
  std::thread producer([&] {
    for (uint32_t i = 0; i < kCount;)
      if (ring.tryPush(i)) ++i;
  });
  uint32_t expected = 0;
  bool ordered = true;
  while (expected < kCount) {
    uint32_t v = 0;
    if (ring.tryPop(v)) ordered = ordered && v == expected++;
  }
  producer.join();
  CHECK(ordered);
  CHECK(ring.empty());
}
