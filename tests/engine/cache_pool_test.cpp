// CachePool's frame shares: what a cache is granted within a frame depends on the pool at the
// frame's start and on that cache's own requests, never on the order in which the tracing
// threads ask (so a render that fills the pool is the same on any number of threads), and the
// budget always holds. A first-come pool fails the order test: with room for one of two
// growths, whichever asks first gets it.
#include <catch2/catch.hpp>
#include <random>
#include <vector>

#include "engine/cache_pool.h"

using dpc::CachePool;

namespace {

/// Grants of two caches' requests within one frame, asked in the given order.
std::vector<bool> grants(const std::vector<std::pair<int, size_t>>& requests, bool reversed) {
  CachePool pool(1000);
  pool.reserveAlways(200);  // the caches' first tables
  pool.beginFrame(2);       // 800 free: 400 per cache this frame
  CachePool::FrameTake take[2];
  std::vector<bool> out(requests.size());
  for (size_t k = 0; k < requests.size(); ++k) {
    const size_t i = reversed ? requests.size() - 1 - k : k;
    out[i] = pool.tryReserve(requests[i].second, take[requests[i].first]);
  }
  return out;
}

}  // namespace

TEST_CASE("Cache pool: grants within a frame do not depend on the order of asking", "[cache]") {
  // Room for one of the two 500-byte growths: first come would grant exactly one of them.
  const std::vector<std::pair<int, size_t>> requests = {{0, 500}, {1, 500}, {0, 300}, {1, 100}};
  const std::vector<bool> forward = grants(requests, false), backward = grants(requests, true);
  CHECK(forward == backward);
  CHECK(forward == std::vector<bool>{false, false, true, true});  // the shares: 400 each
}

TEST_CASE("Cache pool: a growth refused in a frame is granted between frames, in order",
          "[cache]") {
  CachePool pool(1000);
  pool.beginFrame(4);  // 250 per cache
  CachePool::FrameTake a, b;
  CHECK_FALSE(pool.tryReserve(600, a));  // more than a share
  CHECK(pool.refusals() == 1);
  pool.beginFrame(1);  // between frames: the whole free space, caches asked one by one
  CHECK(pool.tryReserve(600, a));
  CHECK_FALSE(pool.tryReserve(600, b));  // 400 left
  CHECK(pool.tryReserve(400, b));
  CHECK(pool.usedBytes() == 1000);
}

TEST_CASE("Cache pool: the budget holds whatever the caches ask", "[cache]") {
  std::mt19937 rng(5);
  CachePool pool(1 << 20);
  std::vector<CachePool::FrameTake> takes(16);
  for (int frame = 0; frame < 50; ++frame) {
    pool.beginFrame(takes.size());
    for (int k = 0; k < 100; ++k) {
      pool.tryReserve(size_t(rng() % 65536), takes[rng() % takes.size()]);
      REQUIRE(pool.usedBytes() <= pool.budgetBytes());
    }
  }
  CHECK(pool.refusals() > 0);  // the pool did fill: the bound was tested
}
