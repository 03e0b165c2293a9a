#include "engine/propagation.h"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <glm/geometric.hpp>
#include <limits>
#include <numbers>

#include "common/air_absorption.h"
#include "engine/patch.h"
#include "engine/reflection_scattering.h"
#include "engine/sampling.h"
#include "engine/transmission.h"

namespace dpc {

namespace {

/// Rays per parallel chunk: long enough that a chunk's packet lanes stay busy while rays of
/// unequal length end (at 256 rays 97 % of lane-segments are live in the shoebox; 4096 rays
/// trace 3 % faster than with 64-ray chunks), short enough that a frame has 16 chunks to share
/// among threads. From the ray count alone, so a frame's result is the same on any number of
/// threads.
uint32_t raysPerChunk(uint32_t rays) {
  return std::clamp(rays / 16u, 64u, 256u);
}

}  // namespace

Bands propagationAirAttenuation(const PropagationSettings& settings) {
  if (!settings.airAbsorption) return Bands(0.f);
  return airEnergyAttenuationPerMetre(settings.temperatureC, settings.humidityPercent);
}

Propagator::Propagator(const Geometry& geometry, const Tracer& tracer,
                       const PropagationSettings& settings, const Options& options)
    : geometry_(geometry),
      tracer_(tracer),
      settings_(settings),
      faceOf_(options.specularFaces),
      reflectionScattering_(options.reflectionScattering),
      traceMode_(options.traceMode) {
  airPerMetre_ = propagationAirAttenuation(settings_);
  minAir_ = airPerMetre_.min();
  const glm::vec3 extent = geometry_.boundsMax() - geometry_.boundsMin();
  keyRule_ = options.keyRule ? *options.keyRule
                             : PathKeyRule::forRoom(double(extent.x) * extent.y * extent.z,
                                                    geometry_.surfaceArea(),
                                                    settings_.speedOfSound, 1e-3);
  exactOrder_ = std::clamp(std::min(settings_.exactOrder, settings_.maxOrder), 0, kMaxExactOrder);
  arena_ = settings_.threads > 0 ? std::make_unique<tbb::task_arena>(settings_.threads)
                                 : std::make_unique<tbb::task_arena>();
}

Propagator::~Propagator() = default;

void Propagator::forEachParallel(size_t n, const std::function<void(size_t)>& f) {
  if (n == 1) {
    f(0);
    return;
  }
  arena_->execute([&] { tbb::parallel_for(size_t(0), n, [&](size_t i) { f(i); }); });
}

int Propagator::concurrency() const {
  return arena_->max_concurrency();
}

DirectSound Propagator::directSound(const glm::vec3& source, const ListenerSphere& listener,
                                    const Directivity& directivity,
                                    const glm::vec3& forward) const {
  DirectSound d;
  const glm::vec3 toListener = listener.position - source;
  const float dist = glm::length(toListener);
  d.distance = std::max(dist, 0.5f * listener.radius);
  d.delaySeconds = d.distance / settings_.speedOfSound;
  d.direction = dist > 0.f ? -toListener / dist : glm::vec3(0.f);
  const PathTransmission through = directTransmission(source, toListener, dist);
  d.visible = !through.blocked;
  d.crossings = through.crossings;
  d.crossingCapped = through.capped;
  if (d.visible) {
    const float spreading = 1.f / (4.f * std::numbers::pi_v<float> * d.distance * d.distance);
    d.intensity = exp(airPerMetre_ * -d.distance) * spreading;
    if (through.crossings > 0) d.intensity *= through.tau;
    // A source at the listener's centre has no direction: its weight is the pattern's mean, 1.
    if (!directivity.omni() && dist > 0.f)
      d.intensity *= directivityWeight(directivity, glm::dot(forward, toListener / dist));
  }
  return d;
}

PathTransmission Propagator::directTransmission(const glm::vec3& source,
                                                const glm::vec3& toListener, float dist) const {
  PathTransmission out;
  if (dist <= 0.f) return out;
  const glm::vec3 dir = toListener / dist;
  const float end = dist * (1.f - 1e-5f);
  if (!geometry_.anyTransmission()) {
    out.blocked = tracer_.occluded(TraceRay{source, dir, 0.f, end});
    return out;
  }
  return transmissionAlong(tracer_, geometry_, source, dir, end);
}

void Propagator::startRay(const Pass& pass, uint32_t rayIndex, RayState& ray) const {
  const TraceRequest& rq = pass.request;
  ray.rng = Rng(pass.frameSeed, rayIndex);
  ray.org = rq.origin;
  ray.dir = uniformSphere(ray.rng);
  ray.firstDir = ray.dir;
  if (geometry_.scatteringVariesWithBand()) {
    // One band per ray, in turn (ray index mod 8: every band gets N/8 rays a frame), carrying
    // kNumBands times its share so each band's energy stays unbiased; its reflections use that
    // band's scattering coefficient.
    ray.band = int(rayIndex % uint32_t(kNumBands));
    ray.bands = uint8_t(1u << ray.band);
    ray.energy = Bands(0.f);
    ray.energy[ray.band] = float(kNumBands);
  } else {
    ray.band = 0;  // every band scatters alike: one ray carries them all
    ray.bands = kAllBands;
    ray.energy = Bands(1.f);
  }
  // The pattern's power-preserving weight at the leaving direction (unbiased: uniform
  // directions times g / <g> have the pattern's angular distribution and the source's power).
  if (!rq.fromListener && !rq.pattern.omni())
    ray.energy *= directivityWeight(rq.pattern, glm::dot(rq.forward, ray.dir));
  ray.travelled = 0.f;
  ray.coherentFrom = 0.f;
  ray.path = PathKey::start(rq.emitter);
  ray.order = 0;
  ray.specularRun = 0;
}

bool Propagator::advance(const TraceRequest& rq, RayState& ray, bool surface,
                         const SurfaceHit& hit, HitList& out, Bands& cut) const {
  const float segEnd = surface ? hit.t : std::numeric_limits<float>::infinity();
  if (ray.order > 0 || rq.includeDirectRays) testListeners(rq, ray, segEnd, out);
  if (!surface) return false;
  if (ray.order >= settings_.maxOrder) {
    cut += ray.energy * exp(airPerMetre_ * -(ray.travelled + hit.t));
    return false;
  }
  return reflect(ray, hit);
}

SpecularSequence Propagator::sourceFirstRun(const RayState& ray, uint32_t k, bool fromListener) {
  SpecularSequence s;
  s.order = k;
  if (fromListener)
    std::reverse_copy(ray.specular.begin(), ray.specular.begin() + k, s.triangles.begin());
  else
    std::copy_n(ray.specular.begin(), k, s.triangles.begin());
  return s;
}

void Propagator::testListeners(const TraceRequest& rq, const RayState& ray, float segEnd,
                               HitList& out) const {
  if (rq.receivers.size() > kMaxLinearSpheres) {
    sphereGrid_.forEachCandidate(ray.org, ray.dir, segEnd,
                                 [&](uint32_t l) { testSphere(rq, ray, segEnd, l, out); });
    return;
  }
  for (uint32_t l = 0; l < rq.receivers.size(); ++l) testSphere(rq, ray, segEnd, l, out);
}

void Propagator::testSphere(const TraceRequest& rq, const RayState& ray, float segEnd, uint32_t l,
                            HitList& out) const {
  const ListenerSphere& listener = rq.receivers[l];
  // Segment against the sphere: |org + t dir - L|^2 = R^2.
  const glm::vec3 oc = listener.position - ray.org;
  const float b = glm::dot(oc, ray.dir);
  const float disc = b * b - (glm::dot(oc, oc) - listener.radius * listener.radius);
  if (!(disc > 0.f)) return;
  const float s = std::sqrt(disc);
  if (!(b + s > 0.f && b - s < segEnd)) return;
  // A hit of an exact specular run carries its sequence (hashed only for segments that meet
  // a sphere); the caller leaves it out when that sequence's exact path is in the frame.
  const bool exact = ray.exactSpecular();
  out.hits.push_back(makeHit(rq, ray, l, b, segEnd));
  out.receiver.push_back(l);
  out.exact.push_back(exact ? 1 : 0);
  out.sequence.push_back(
      exact ? sourceFirstRun(ray, uint32_t(ray.specularRun), rq.fromListener).key() : 0);
}

void Propagator::prepareSpheres(std::span<const ListenerSphere> listeners) {
  if (listeners.size() <= kMaxLinearSpheres) return;
  sphereBoxes_.clear();
  for (const ListenerSphere& l : listeners) sphereBoxes_.emplace_back(l.position, l.radius);
  sphereGrid_.build(sphereBoxes_);
}

PathHit Propagator::makeHit(const TraceRequest& rq, const RayState& ray, uint32_t l, float b,
                            float segEnd) const {
  const ListenerSphere& sphere = rq.receivers[l];
  const float invArea = 1.f / (std::numbers::pi_v<float> * sphere.radius * sphere.radius);
  const float r = ray.travelled + std::clamp(b, 0.f, segEnd);
  PathHit h;
  h.key = ray.path.finish(l < rq.receiverIds.size() ? rq.receiverIds[l] : l, r, keyRule_,
                          rq.fromListener);
  h.intensity = ray.energy * exp(airPerMetre_ * -r) * invArea;
  h.length = r;
  if (ray.path.order > 0)
    h.surface = rq.fromListener ? ray.path.firstTriangle : ray.path.lastTriangle;
  if (!rq.fromListener) {
    h.direction = -ray.dir;
    return h;
  }
  // Reciprocal path: the sound leaves source l along -dir and reaches the listener from firstDir.
  h.direction = ray.firstDir;
  if (l < rq.receiverPatterns.size() && !rq.receiverPatterns[l].omni())
    h.intensity *=
        directivityWeight(rq.receiverPatterns[l], glm::dot(rq.receiverForwards[l], -ray.dir));
  return h;
}

bool Propagator::belowRouletteThreshold(const RayState& ray) const {
  // Whether energy x e^(-minAir d) < threshold, with e^(-x) taken only where it matters:
  // 1 - x <= e^(-x) <= 1 bound it, and most reflections are decided by the bounds alone.
  const float e = ray.energy.max(), x = minAir_ * ray.travelled;
  const float threshold = settings_.rouletteThreshold;
  if (e < threshold) return true;
  if (e * (1.f - x) >= threshold) return false;
  return e * std::exp(-x) < threshold;
}

bool Propagator::reflect(RayState& ray, const SurfaceHit& hit) const {
  ray.travelled += hit.t;
  const glm::vec3 p = ray.org + ray.dir * hit.t;
  if (ray.path.nextNeedsPatch(keyRule_)) {
    const auto [zeta, xi] = geometry_.patching(hit.triangle).patchOf(hit.barycentric);
    ray.path.add(hit.triangle, zeta, xi);
  } else {
    ray.path.addTriangle(hit.triangle);
  }
  // A transmitting surface: reflect or pass through (engine/transmission.h); one more random
  // draw only there, so an opaque scene's rays draw and compute as without transmission.
  bool through = false;
  if (geometry_.transmits(hit.triangle))
    through =
        chooseTransmission(geometry_.reflectance(hit.triangle),
                           geometry_.transmittance(hit.triangle), ray.rng.uniform(), ray.energy);
  else
    ray.energy *= geometry_.reflectance(hit.triangle);
  if (settings_.rouletteThreshold > 0.f && belowRouletteThreshold(ray)) {
    if (ray.rng.uniform() >= kRouletteSurvival) return false;
    ray.energy *= 1.f / kRouletteSurvival;
  }
  if (through) {  // same direction, on the far side; a transmission ends the specular run
    ray.org = p + ray.dir * surfaceOffset(p, hit.t);
    ++ray.order;
    return true;
  }
  // Normal facing the side the ray came from.
  const glm::vec3 n = glm::dot(hit.normal, ray.dir) < 0.f ? hit.normal : -hit.normal;
  const glm::vec3 org = p + n * surfaceOffset(p, hit.t);
  const glm::vec3 mirrored = glm::normalize(ray.dir - 2.f * glm::dot(ray.dir, n) * n);
  const bool diffuse = scatters(ray, hit, org, n, mirrored);
  if (diffuse) {
    ray.dir = cosineHemisphere(n, ray.rng);
    ray.coherentFrom = ray.travelled;
  } else {
    ray.dir = mirrored;
  }
  ray.org = org;
  if (!diffuse && ray.specularRun == ray.order && ray.order < exactOrder_)
    ray.specular[size_t(ray.specularRun++)] = faceOf(hit.triangle);
  ++ray.order;
  return true;
}

bool Propagator::scatters(RayState& ray, const SurfaceHit& hit, const glm::vec3& org,
                          const glm::vec3& n, const glm::vec3& mirrored) const {
  const Bands& s = geometry_.scattering(hit.triangle);
  const ReflectionScattering* rs = reflectionScattering_;
  if (!rs || !rs->standsFree(hit.triangle, n, hit.normal)) return ray.rng.uniform() < s[ray.band];
  const ReflectionScattering::Reflection r{
      hit.triangle, org, ray.dir, n, mirrored, ray.travelled - ray.coherentFrom};
  if (std::popcount(ray.bands) > 1) {  // narrowed to bands the face treats alike
    ray.bands = rs->narrow(r, settings_.speedOfSound, ray.bands, ray.rng, ray.energy);
    ray.band = std::countr_zero(ray.bands);
  }
  return rs->scatters(tracer_, r, settings_.speedOfSound, s[ray.band], ray.band, ray.rng.uniform());
}

void Propagator::traceRay(const Pass& pass, uint32_t rayIndex, Chunk& chunk) const {
  RayState ray;
  startRay(pass, rayIndex, ray);
  SurfaceHit hit;
  for (;;) {
    const bool surface = tracer_.intersect(TraceRay{ray.org, ray.dir}, hit);
    ++chunk.segments;
    if (!advance(pass.request, ray, surface, hit, chunk.ordered, chunk.maxOrderEnergy)) break;
  }
  noteSpecularRun(ray, chunk);
}

void Propagator::noteSpecularRun(const RayState& ray, Chunk& chunk) const {
  if (ray.specularRun == 0) return;
  SpecularSequence s;  // as recorded; collectCandidates orients every prefix
  s.order = uint32_t(ray.specularRun);
  std::copy_n(ray.specular.begin(), ray.specularRun, s.triangles.begin());
  chunk.specularRuns.push_back(s);
}

void Propagator::collectCandidates(uint32_t chunkCount, SpecularCandidates& candidates,
                                   bool listenerFirst) const {
  for (uint32_t c = 0; c < chunkCount; ++c)
    for (const SpecularSequence& run : chunks_[c].specularRuns)
      for (uint32_t k = 1; k <= run.order; ++k) {
        // A prefix is the path's first k reflections from the emitter: from a listener, the
        // source-first sequence is its reverse.
        SpecularSequence p = run.prefix(k);
        if (listenerFirst) std::reverse(p.triangles.begin(), p.triangles.begin() + k);
        candidates.insert(p);
      }
}

void Propagator::traceChunkPacket(const Pass& pass, uint32_t firstRay, uint32_t endRay,
                                  Chunk& chunk) const {
  constexpr int K = int(Tracer::kPacketSize);
  std::array<RayState, K> rays;
  std::array<uint32_t, K> rayIndex{};
  std::array<TraceRay, K> packet;  // org and dir of live lanes; tnear 0, tfar infinity
  std::array<TraceHit, K> answers;
  chunk.unordered.clear();
  chunk.rayOf.clear();
  uint32_t next = firstRay;
  // Lanes are filled in ray order and refilled, lowest lane first, as rays end: a fixed
  // schedule, independent of threads. A lane stays idle once the chunk has no rays left.
  auto refill = [&](int i) {
    packet[i].active = next < endRay;
    if (packet[i].active) {
      startRay(pass, next, rays[i]);
      rayIndex[i] = next++;
    }
    return packet[i].active;
  };
  int live = 0;
  for (int i = 0; i < K; ++i) live += refill(i) ? 1 : 0;
  while (live > 0) {
    for (int i = 0; i < K; ++i)
      if (packet[i].active) {
        packet[i].org = rays[i].org;
        packet[i].dir = rays[i].dir;
      }
    tracer_.intersect(packet, answers);
    chunk.segments += uint64_t(live);
    for (int i = 0; i < K; ++i) {
      if (!packet[i].active) continue;
      const bool more = advance(pass.request, rays[i], answers[i].found, answers[i].surface,
                                chunk.unordered, chunk.maxOrderEnergy);
      while (chunk.rayOf.size() < chunk.unordered.hits.size())  // one hit per receiver at most
        chunk.rayOf.push_back(rayIndex[i] - firstRay);
      if (!more) noteSpecularRun(rays[i], chunk);
      if (!more && !refill(i)) --live;
    }
  }
  chunk.sortByRay(endRay - firstRay);
}

void Propagator::Chunk::sortByRay(uint32_t count) {
  // Counting sort; stable, so each ray's hits stay in reflection order.
  offsets.assign(count + 1, 0);
  for (uint32_t r : rayOf) ++offsets[r + 1];
  for (uint32_t r = 0; r < count; ++r) offsets[r + 1] += offsets[r];
  ordered.resize(unordered.hits.size());
  for (size_t h = 0; h < unordered.hits.size(); ++h) ordered.copy(h, unordered, offsets[rayOf[h]]++);
}

std::pair<uint32_t, uint32_t> Propagator::chunksFor(int rays) {
  const uint32_t n = uint32_t(std::max(0, rays));
  const uint32_t perChunk = raysPerChunk(n);
  const uint32_t chunkCount = (n + perChunk - 1) / perChunk;
  if (chunks_.size() < chunkCount) chunks_.resize(chunkCount);
  return {chunkCount, perChunk};
}

TraceStats Propagator::traceFrame(const TraceRequest& request, FrameGroups& groups) {
  FrameGroups* const g = &groups;
  return traceFrame(request, std::span(&g, 1));
}

TraceStats Propagator::traceFrame(const TraceRequest& request,
                                  std::span<FrameGroups* const> groups,
                                  SpecularCandidates* candidates) {
  if (scratchHits_.size() < groups.size()) scratchHits_.resize(groups.size());
  scratchPtrs_.clear();
  for (size_t l = 0; l < groups.size(); ++l) {
    scratchHits_[l].clear();
    scratchPtrs_.push_back(&scratchHits_[l]);
  }
  const TraceStats stats = traceFrame(request, std::span(scratchPtrs_), candidates);
  for (size_t l = 0; l < groups.size(); ++l) scratchHits_[l].groupInto(*groups[l], nullptr);
  return stats;
}

TraceStats Propagator::traceFrame(const TraceRequest& request, std::span<FrameHits* const> hits,
                                  SpecularCandidates* candidates) {
  const uint32_t n = uint32_t(std::max(0, request.rays));
  const std::pair<uint32_t, uint32_t> chunks = chunksFor(request.rays);
  const uint32_t chunkCount = chunks.first, perChunk = chunks.second;
  const Pass pass{request, hashCombine(hashCombine(request.seed, request.frame),
                                       uint64_t(request.emitter))};
  prepareSpheres(request.receivers);
  arena_->execute([&] {
    tbb::parallel_for(uint32_t(0), chunkCount, [&](uint32_t c) {
      Chunk& chunk = chunks_[c];
      chunk.ordered.clear();
      chunk.specularRuns.clear();
      chunk.segments = 0;
      chunk.maxOrderEnergy = Bands(0.f);
      const uint32_t end = std::min(n, (c + 1) * perChunk);
      if (traceMode_ == TraceMode::kPacket16) {
        traceChunkPacket(pass, c * perChunk, end, chunk);
        return;
      }
      for (uint32_t ray = c * perChunk; ray < end; ++ray) traceRay(pass, ray, chunk);
    });
  });
  TraceStats stats;
  stats.rays = n;
  for (uint32_t c = 0; c < chunkCount; ++c) {
    const Chunk& chunk = chunks_[c];
    stats.segments += chunk.segments;
    stats.maxOrderEnergy += chunk.maxOrderEnergy;
    const HitList& list = chunk.ordered;
    stats.listenerHits += list.hits.size();
    for (size_t h = 0; h < list.hits.size(); ++h)
      hits[list.receiver[h]]->add(list.hits[h], list.exact[h] != 0, list.sequence[h]);
  }
  if (candidates && exactOrder_ > 0)
    collectCandidates(chunkCount, *candidates, request.fromListener);
  return stats;
}

void Propagator::mirrorRun(uint64_t frameSeed, uint32_t rayIndex, const glm::vec3& from,
                           Chunk& chunk) const {
  Rng rng(frameSeed, rayIndex);
  TraceRay ray{from, uniformSphere(rng)};
  SpecularSequence run;
  SurfaceHit hit;
  while (run.order < uint32_t(exactOrder_) && tracer_.intersect(ray, hit)) {
    ++chunk.segments;
    run.triangles[run.order++] = faceOf(hit.triangle);
    // Mirror reflection about the normal facing the side the ray came from (reflect()).
    const glm::vec3 n = glm::dot(hit.normal, ray.dir) < 0.f ? hit.normal : -hit.normal;
    const glm::vec3 p = ray.org + ray.dir * hit.t;
    ray.org = p + n * surfaceOffset(p, hit.t);
    ray.dir = glm::normalize(ray.dir - 2.f * glm::dot(ray.dir, n) * n);
  }
  if (run.order > 0) chunk.specularRuns.push_back(run);
}

TraceStats Propagator::proposeSpecular(const TraceRequest& request,
                                       SpecularCandidates& candidates) {
  TraceStats stats;
  if (exactOrder_ == 0) return stats;
  // Salt that keeps these streams apart from traceFrame's (seed, frame, emitter) streams.
  constexpr uint64_t kProposalSalt = 0x9e3779b97f4a7c15ULL;
  const uint32_t n = uint32_t(std::max(0, request.rays));
  const std::pair<uint32_t, uint32_t> chunks = chunksFor(request.rays);
  const uint32_t chunkCount = chunks.first, perChunk = chunks.second;
  const glm::vec3 position = request.origin;
  const uint64_t frameSeed = hashCombine(
      hashCombine(hashCombine(request.seed, request.frame), kProposalSalt), request.emitter);
  arena_->execute([&] {
    tbb::parallel_for(uint32_t(0), chunkCount, [&](uint32_t c) {
      Chunk& chunk = chunks_[c];
      chunk.specularRuns.clear();
      chunk.segments = 0;
      for (uint32_t r = c * perChunk; r < std::min(n, (c + 1) * perChunk); ++r)
        mirrorRun(frameSeed, r, position, chunk);
    });
  });
  stats.rays = n;
  for (uint32_t c = 0; c < chunkCount; ++c) stats.segments += chunks_[c].segments;
  collectCandidates(chunkCount, candidates, true);
  return stats;
}

}  // namespace dpc
