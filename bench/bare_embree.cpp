#include "bench/bare_embree.h"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <array>
#include <chrono>
#include <cmath>
#include <glm/geometric.hpp>
#include <limits>
#include <numbers>
#include <vector>

#include "common/random.h"
#include "engine/sampling.h"

namespace dpc::bench {

namespace {

constexpr uint32_t kChunk = 64;

/// Cosine-weighted bounce; moves org to the hit point.
void bounce(const SurfaceHit& hit, Rng& rng, glm::vec3& org, glm::vec3& dir) {
  const glm::vec3 n = glm::dot(hit.normal, dir) < 0.f ? hit.normal : -hit.normal;
  org = org + dir * hit.t + n * 1e-4f;
  dir = cosineHemisphere(n, rng);
}

uint64_t scalarChunk(const Tracer& tracer, const glm::vec3& source, uint32_t begin, uint32_t end,
                     int maxOrder, uint64_t seed) {
  uint64_t count = 0;
  for (uint32_t ray = begin; ray < end; ++ray) {
    Rng rng(seed, ray);
    glm::vec3 dir = uniformSphere(rng), org = source;
    SurfaceHit hit;
    for (int order = 0; order <= maxOrder; ++order) {
      ++count;
      if (!tracer.intersect(TraceRay{org, dir}, hit)) break;
      bounce(hit, rng, org, dir);
    }
  }
  return count;
}

uint64_t packetChunk(const Tracer& tracer, const glm::vec3& source, uint32_t begin, uint32_t end,
                     int maxOrder, uint64_t seed) {
  constexpr int K = int(Tracer::kPacketSize);
  struct Lane {
    Rng rng{0, 0};
    int order = 0;
  };
  std::array<Lane, K> lanes;
  std::array<TraceRay, K> packet;
  std::array<TraceHit, K> hits;
  uint64_t count = 0;
  uint32_t next = begin;
  int live = 0;
  auto start = [&](int i) {
    lanes[i].rng = Rng(seed, next++);
    packet[i].dir = uniformSphere(lanes[i].rng);
    packet[i].org = source;
    lanes[i].order = 0;
  };
  for (int i = 0; i < K; ++i) {
    packet[i].active = next < end;
    if (!packet[i].active) continue;
    start(i);
    ++live;
  }
  while (live > 0) {
    tracer.intersect(packet, hits);
    count += uint64_t(live);
    for (int i = 0; i < K; ++i) {
      if (!packet[i].active) continue;
      if (hits[i].found && lanes[i].order < maxOrder) {
        bounce(hits[i].surface, lanes[i].rng, packet[i].org, packet[i].dir);
        ++lanes[i].order;
      } else if (next < end) {
        start(i);
      } else {
        packet[i].active = false;
        --live;
      }
    }
  }
  return count;
}

}  // namespace

BareResult traceBare(const Tracer& tracer, const glm::vec3& source, int rays, int maxOrder,
                     int threads, uint64_t seed, BareMode mode) {
  const uint32_t chunks = (uint32_t(rays) + kChunk - 1) / kChunk;
  std::vector<uint64_t> segments(chunks, 0);
  tbb::task_arena arena = threads > 0 ? tbb::task_arena(threads) : tbb::task_arena();
  const auto t0 = std::chrono::steady_clock::now();
  arena.execute([&] {
    tbb::parallel_for(uint32_t(0), chunks, [&](uint32_t c) {
      const uint32_t begin = c * kChunk, end = std::min(uint32_t(rays), (c + 1) * kChunk);
      segments[c] = mode == BareMode::kPacket16
                        ? packetChunk(tracer, source, begin, end, maxOrder, seed)
                        : scalarChunk(tracer, source, begin, end, maxOrder, seed);
    });
  });
  BareResult r;
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  for (uint64_t s : segments) r.segments += s;
  return r;
}

}  // namespace dpc::bench
