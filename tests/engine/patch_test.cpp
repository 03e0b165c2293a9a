#include "engine/patch.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <map>
#include <set>
#include <unordered_set>

#include "common/random.h"

using namespace dpc;

namespace {
glm::vec3 pointOf(const std::array<glm::vec3, 3>& p, const std::array<float, 3>& g) {
  return p[0] * g[0] + p[1] * g[1] + p[2] * g[2];
}
}  // namespace

TEST_CASE("Key vertex is opposite the shortest edge, counts as defined", "[patch]") {
  // Right triangle with legs 4 (x) and 3 (y): edges 3, 4, 5; shortest edge (3) is opposite
  // vertex 1 at (4,0,0): altitude h = 2A / 3 = 12 / 3 = 4.
  const glm::vec3 a(0, 0, 0), b(4, 0, 0), c(0, 3, 0);
  const float lambda = 0.5f;
  const TrianglePatching t = TrianglePatching::build(a, b, c, lambda);
  CHECK(t.keyVertex == 1);
  CHECK(t.rows == 8);           // ceil(4 / 0.5)
  CHECK(t.widestColumns == 6);  // ceil(3 / 0.5)
  // Eq. 3.1: ceil((N_zeta - zeta) / N_zeta * N_xi).
  for (uint32_t z = 0; z < t.rows; ++z)
    CHECK(t.columnsInRow(z) == uint32_t(std::ceil((8.0 - z) / 8.0 * 6.0 - 1e-12)));
  CHECK(sizeof(TrianglePatching) <= 6);
}

TEST_CASE("Patches are about lambda in extent and area, and ids are unique", "[patch][heavy]") {
  Rng rng(7, 1);
  const float lambda = 0.25f;
  for (int trial = 0; trial < 20; ++trial) {
    std::array<glm::vec3, 3> p;
    for (auto& v : p) v = glm::vec3(rng.uniform(), rng.uniform(), rng.uniform()) * 6.f;
    const double area = 0.5 * glm::length(glm::cross(p[1] - p[0], p[2] - p[0]));
    if (area < 2.0) continue;  // skip slivers: "about lambda" needs a triangle many lambdas big
    const TrianglePatching t = TrianglePatching::build(p[0], p[1], p[2], lambda);
    // Sample the triangle uniformly; record every patch's share and bounding extent.
    // Triangle frame: x along the edge e_k opposite the key vertex, y along its altitude.
    const int k = t.keyVertex;
    const glm::vec3 apex = p[size_t(k)], e0 = p[size_t((k + 1) % 3)], e1 = p[size_t((k + 2) % 3)];
    const glm::vec3 xAxis = glm::normalize(e1 - e0);
    const glm::vec3 foot = e0 + xAxis * glm::dot(apex - e0, xAxis);
    const float hk = glm::length(apex - foot);
    const glm::vec3 yAxis = (apex - foot) / hk;
    struct Stat {
      int count = 0;
      glm::vec2 lo{1e9f}, hi{-1e9f};
    };
    std::map<std::pair<uint32_t, uint32_t>, Stat> stats;
    const int samples = 400000;
    for (int i = 0; i < samples; ++i) {
      float u = rng.uniform(), v = rng.uniform();
      if (u + v > 1.f) u = 1.f - u, v = 1.f - v;
      const std::array<float, 3> g = {1.f - u - v, u, v};
      const auto id = t.patchOf(g);
      REQUIRE(id[0] < t.rows);
      REQUIRE(id[1] < t.columnsInRow(id[0]));
      Stat& s = stats[{id[0], id[1]}];
      ++s.count;
      const glm::vec3 q = pointOf(p, g) - foot;
      const glm::vec2 xy(glm::dot(q, xAxis), glm::dot(q, yAxis));
      s.lo = glm::min(s.lo, xy);
      s.hi = glm::max(s.hi, xy);
    }
    // Every patch of the subdivision is reached (ids unique and all used).
    CHECK(stats.size() == t.patchCount());
    // Mean patch area = area / count; rows are h/ceil(h/lambda) <= lambda tall and columns
    // at most lambda wide at their widest, so the mean lies in (lambda^2/4, lambda^2].
    const double mean = area / double(t.patchCount());
    CHECK(mean <= double(lambda) * lambda * 1.0001);
    CHECK(mean > 0.25 * lambda * lambda);
    // Extent: a patch lies between two row lines at most lambda apart (parallel to e_k) and
    // two column lines through the key vertex, at most lambda apart where the row is widest.
    // A column line drifts sideways by s = (offset of its base point from the altitude's
    // foot) / h_k per unit of height, so along the altitude the extent is <= lambda and along
    // the edge <= lambda (1 + s). Area <= lambda^2 (from sample counts, +10 % for MC error).
    const float shear = std::max(glm::length(e0 - foot), glm::length(e1 - foot)) / hk;
    for (const auto& [id, s] : stats) {
      CHECK(s.hi.y - s.lo.y <= lambda * 1.001f);
      CHECK(s.hi.x - s.lo.x <= lambda * (1.f + shear) * 1.001f);
      CHECK(area * s.count / samples <= 1.1 * lambda * lambda);
    }
  }
}

TEST_CASE("Path hash: order-sensitive and collision-free over a million paths",
          "[patch][statistics]") {
  const uint64_t h0 = pathHashStart(0);
  const uint64_t ab = pathHashAddPatch(pathHashAddPatch(h0, patchKey(1, 0, 0)), patchKey(2, 0, 0));
  const uint64_t ba = pathHashAddPatch(pathHashAddPatch(h0, patchKey(2, 0, 0)), patchKey(1, 0, 0));
  CHECK(ab != ba);
  CHECK(pathHashFinish(ab, 0) != pathHashFinish(ab, 1));
  CHECK(pathHashStart(0) != pathHashStart(1));
  // One million distinct random patch sequences of orders 1..8 over a small scene (many
  // shared prefixes): a 64-bit hash has a birthday collision chance of ~3e-8 here.
  Rng rng(11, 3);
  std::unordered_set<uint64_t> seen;
  std::set<std::vector<uint64_t>> sequences;
  seen.reserve(1 << 21);
  size_t distinct = 0;
  while (distinct < 1000000) {
    const int order = 1 + int(rng.nextU32() % 8);
    std::vector<uint64_t> seq;
    uint64_t h = pathHashStart(0);
    for (int d = 0; d < order; ++d) {
      seq.push_back(patchKey(rng.nextU32() % 12, rng.nextU32() % 20, rng.nextU32() % 20));
      h = pathHashAddPatch(h, seq.back());
    }
    if (!sequences.insert(seq).second) continue;  // same sequence drawn twice: not a collision
    ++distinct;
    REQUIRE(seen.insert(pathHashFinish(h, 0)).second);
  }
}
