#include "bench/bare_embree.h"

#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include <glm/geometric.hpp>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "engine/random.h"

namespace dpc::bench {

BareResult traceBare(const Geometry& geometry, const glm::vec3& source, int rays, int maxOrder,
                     int threads, uint64_t seed) {
  constexpr uint32_t kChunk = 64;
  const uint32_t chunks = (uint32_t(rays) + kChunk - 1) / kChunk;
  std::vector<uint64_t> segments(chunks, 0);
  tbb::task_arena arena = threads > 0 ? tbb::task_arena(threads) : tbb::task_arena();
  const auto t0 = std::chrono::steady_clock::now();
  arena.execute([&] {
    tbb::parallel_for(uint32_t(0), chunks, [&](uint32_t c) {
      uint64_t count = 0;
      const uint32_t end = std::min(uint32_t(rays), (c + 1) * kChunk);
      for (uint32_t ray = c * kChunk; ray < end; ++ray) {
        Rng rng(seed, ray);
        const float z = 1.f - 2.f * rng.uniform();
        const float r = std::sqrt(std::max(0.f, 1.f - z * z));
        const float phi = 2.f * std::numbers::pi_v<float> * rng.uniform();
        glm::vec3 dir(r * std::cos(phi), r * std::sin(phi), z), org = source;
        SurfaceHit hit;
        for (int order = 0; order <= maxOrder; ++order) {
          ++count;
          if (!geometry.intersect(org, dir, 0.f, std::numeric_limits<float>::infinity(), hit))
            break;
          const glm::vec3 n = glm::dot(hit.normal, dir) < 0.f ? hit.normal : -hit.normal;
          // Cosine-weighted bounce (Malley), basis after Duff et al. 2017.
          const float sign = std::copysign(1.f, n.z);
          const float a = -1.f / (sign + n.z), b = n.x * n.y * a;
          const glm::vec3 t(1.f + sign * n.x * n.x * a, sign * b, -sign * n.x);
          const glm::vec3 bt(b, sign + n.y * n.y * a, -n.y);
          const float u1 = rng.uniform(), u2 = rng.uniform();
          const float rr = std::sqrt(u1), ph = 2.f * std::numbers::pi_v<float> * u2;
          org = org + dir * hit.t + n * 1e-4f;
          dir = glm::normalize(t * (rr * std::cos(ph)) + bt * (rr * std::sin(ph)) +
                               n * std::sqrt(std::max(0.f, 1.f - u1)));
        }
      }
      segments[c] = count;
    });
  });
  BareResult r;
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  for (uint64_t s : segments) r.segments += s;
  return r;
}

}  // namespace dpc::bench
