#include "engine/propagation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <glm/geometric.hpp>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "engine/air_absorption.h"
#include "engine/patch.h"
#include "engine/random.h"

namespace dpc {

namespace {

constexpr uint32_t kRaysPerChunk = 64;

glm::vec3 uniformSphere(Rng& rng) {
  const float z = 1.f - 2.f * rng.uniform();
  const float r = std::sqrt(std::max(0.f, 1.f - z * z));
  const float phi = 2.f * std::numbers::pi_v<float> * rng.uniform();
  return {r * std::cos(phi), r * std::sin(phi), z};
}

/// Cosine-weighted direction about unit normal n (Malley's method). The orthonormal basis is
/// Duff et al., "Building an Orthonormal Basis, Revisited", JCGT 6(1), 2017.
glm::vec3 cosineHemisphere(const glm::vec3& n, Rng& rng) {
  const float sign = std::copysign(1.f, n.z);
  const float a = -1.f / (sign + n.z);
  const float b = n.x * n.y * a;
  const glm::vec3 t(1.f + sign * n.x * n.x * a, sign * b, -sign * n.x);
  const glm::vec3 bt(b, sign + n.y * n.y * a, -n.y);
  const float u1 = rng.uniform(), u2 = rng.uniform();
  const float r = std::sqrt(u1);
  const float phi = 2.f * std::numbers::pi_v<float> * u2;
  const float z = std::sqrt(std::max(0.f, 1.f - u1));
  return glm::normalize(t * (r * std::cos(phi)) + bt * (r * std::sin(phi)) + n * z);
}

}  // namespace

Propagator::Propagator(const Geometry& geometry, const PropagationSettings& settings)
    : geometry_(geometry), settings_(settings) {
  if (settings_.airAbsorption)
    airPerMetre_ = airEnergyAttenuationPerMetre(settings_.temperatureC, settings_.humidityPercent);
  minAir_ = airPerMetre_.min();
  const glm::vec3 extent = geometry_.boundsMax() - geometry_.boundsMin();
  epsilon_ = 1e-5f * std::max(10.f, std::max(extent.x, std::max(extent.y, extent.z)));
  arena_ = settings_.threads > 0 ? std::make_unique<tbb::task_arena>(settings_.threads)
                                 : std::make_unique<tbb::task_arena>();
}

Propagator::~Propagator() = default;

DirectSound Propagator::directSound(const glm::vec3& source,
                                    const ListenerSphere& listener) const {
  DirectSound d;
  const glm::vec3 toListener = listener.position - source;
  const float dist = glm::length(toListener);
  d.distance = std::max(dist, 0.5f * listener.radius);
  d.delaySeconds = d.distance / settings_.speedOfSound;
  d.direction = dist > 0.f ? -toListener / dist : glm::vec3(0.f);
  d.visible = dist <= 0.f ||
              !geometry_.occluded(source, toListener / dist, 0.f, dist * (1.f - 1e-5f));
  if (d.visible) {
    const float spreading = 1.f / (4.f * std::numbers::pi_v<float> * d.distance * d.distance);
    d.intensity = exp(airPerMetre_ * -d.distance) * spreading;
  }
  return d;
}

void Propagator::traceRay(uint64_t frameSeed, uint32_t sourceIndex, uint32_t rayIndex,
                          const glm::vec3& source, const ListenerSphere& listener,
                          std::vector<PathHit>& hits, uint64_t& segments) const {
  Rng rng(frameSeed, rayIndex);
  const float inf = std::numeric_limits<float>::infinity();
  const float r2 = listener.radius * listener.radius;
  const float invArea = 1.f / (std::numbers::pi_v<float> * r2);
  glm::vec3 org = source;
  glm::vec3 dir = uniformSphere(rng);
  Bands energy(1.f);
  float travelled = 0.f;
  uint64_t pathHash = pathHashStart(sourceIndex);
  SurfaceHit hit;
  for (int order = 0;; ++order) {
    const bool surface = geometry_.intersect(org, dir, 0.f, inf, hit);
    ++segments;
    const float segEnd = surface ? hit.t : inf;
    if (order > 0 || includeDirectRays_) {
      // Segment against the listener sphere: |org + t dir - L|^2 = R^2.
      const glm::vec3 oc = listener.position - org;
      const float b = glm::dot(oc, dir);
      const float disc = b * b - (glm::dot(oc, oc) - r2);
      if (disc > 0.f) {
        const float s = std::sqrt(disc);
        if (b + s > 0.f && b - s < segEnd) {
          const float r = travelled + std::clamp(b, 0.f, segEnd);
          PathHit h;
          h.key = pathHashFinish(pathHash, 0);
          h.intensity = energy * exp(airPerMetre_ * -r) * invArea;
          h.length = r;
          h.direction = -dir;
          hits.push_back(h);
        }
      }
    }
    if (!surface || order >= settings_.maxOrder) break;
    travelled += hit.t;
    const glm::vec3 p = org + dir * hit.t;
    const TrianglePatching& patching = geometry_.patching(hit.triangle);
    const auto [zeta, xi] = patching.patchOf(hit.barycentric);
    pathHash = pathHashAddPatch(pathHash, patchKey(hit.triangle, zeta, xi));
    energy *= geometry_.reflectance(hit.triangle);
    if (settings_.rouletteThreshold > 0.f &&
        energy.max() * std::exp(-minAir_ * travelled) < settings_.rouletteThreshold) {
      if (rng.uniform() >= kRouletteSurvival) break;
      energy *= 1.f / kRouletteSurvival;
    }
    // Normal facing the side the ray came from.
    const glm::vec3 n = glm::dot(hit.normal, dir) < 0.f ? hit.normal : -hit.normal;
    if (rng.uniform() < geometry_.scattering(hit.triangle))
      dir = cosineHemisphere(n, rng);
    else
      dir = glm::normalize(dir - 2.f * glm::dot(dir, n) * n);
    org = p + n * epsilon_;
  }
}

TraceStats Propagator::traceFrame(uint64_t frameIndex, uint32_t sourceIndex,
                                  const glm::vec3& source, const ListenerSphere& listener,
                                  FrameGroups& groups) {
  const uint32_t n = uint32_t(std::max(0, settings_.raysPerFrame));
  const uint32_t chunkCount = (n + kRaysPerChunk - 1) / kRaysPerChunk;
  if (chunks_.size() < chunkCount) chunks_.resize(chunkCount);
  const uint64_t frameSeed =
      hashCombine(hashCombine(settings_.seed, frameIndex), uint64_t(sourceIndex));
  arena_->execute([&] {
    tbb::parallel_for(uint32_t(0), chunkCount, [&](uint32_t c) {
      Chunk& chunk = chunks_[c];
      chunk.hits.clear();
      chunk.segments = 0;
      const uint32_t end = std::min(n, (c + 1) * kRaysPerChunk);
      for (uint32_t ray = c * kRaysPerChunk; ray < end; ++ray)
        traceRay(frameSeed, sourceIndex, ray, source, listener, chunk.hits, chunk.segments);
    });
  });
  TraceStats stats;
  stats.rays = n;
  for (uint32_t c = 0; c < chunkCount; ++c) {
    stats.segments += chunks_[c].segments;
    stats.listenerHits += chunks_[c].hits.size();
    for (const PathHit& h : chunks_[c].hits) groups.add(h);
  }
  return stats;
}

}  // namespace dpc
