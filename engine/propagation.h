// Monte Carlo sound propagation from a point source through the scene (one frame).
//
// Each frame emits N uniformly distributed rays from a source. A ray reflects up to
// max_order times: at each hit its band energy is multiplied by (1 - absorption); with
// probability `scattering` (off a small free-standing face 1 - (1 - scattering) K,
// engine/reflection_scattering.h) it leaves in a cosine-weighted (Lambert) direction,
// otherwise in the mirror direction. Every segment (including the one leaving the source only when
// includeDirectRays is set; the direct sound is otherwise analytic) is tested against the
// listener sphere of radius R; a crossing adds a PathHit with
//   I(omega) = energy(omega) * exp(-m(omega) r) / (pi R^2),
// r the path length to the point of closest approach to the listener's centre, m the
// ISO 9613-1 air attenuation. Dividing by N gives intensity relative to the source power on
// the scale of the direct sound 1/(4 pi r^2) (docs/design.md, "Energy convention").
// At a surface whose material transmits (engine/transmission.h) the ray instead passes
// through, keeping its direction, with probability p and energy weight tau/p, or reflects with
// weight (1 - alpha)/(1 - p); the crossing counts as an order and ends the specular run.
// The path identifier (engine/patch.h) is hashed incrementally, one patch per reflection.
// Russian roulette (Arvo & Kirk, "Particle transport and image synthesis", SIGGRAPH 1990):
// once a ray's band energy times the air attenuation of its lowest band has fallen below
// settings.rouletteThreshold in every band, it continues with probability kRouletteSurvival
// carrying 1/kRouletteSurvival times its energy, or ends: unbiased, and tails no longer stop
// at an arbitrary max_order.
//
// Threads: traceFrame runs on the propagation thread and fans the rays out over TBB worker
// threads in fixed chunks; every ray has its own random stream derived from (seed, frame,
// source, ray), and chunks are merged in ray order, so the result is bit-identical for a seed
// whatever the thread count.
// Queries go through the Tracer interface (engine/tracer.h); materials and patches come from
// Geometry.
// Packet tracing (TraceMode::kPacket16): each chunk keeps 16 of its rays in flight in
// lockstep, one batch query of Tracer::kPacketSize rays per step for the live lanes (the
// Embree tracer's rtcIntersect16; Wald et al., "Interactive
// rendering with coherent ray tracing", 2001; Embree's hybrid traversal for incoherent
// packets); a lane whose ray ends takes the chunk's next ray. Every ray keeps its own random
// stream and its own per-ray arithmetic (the same code as the scalar path), and the chunk's
// hits are put back in (ray, reflection order) order, so the result is again bit-identical
// for a seed whatever the thread count; it equals the scalar path's up to the rounding of
// the packet kernels (statistically equal: tests/engine/packet_test.cpp). Allocation:
// per-chunk hit buffers grow to their high-water mark, then are reused. No errors.
// Exact early specular paths (settings.exactOrder = N > 0; engine/specular_paths.h): each ray
// remembers the triangles of its leading reflections while every one chose the specular lobe,
// up to N; traceFrame hands these sequences (and their prefixes) out as image-source
// candidates, and a listener hit of a ray whose reflections so far are all specular and at
// most N is left out of the groups, because the exact path replaces it in expectation
// (docs/estimators.md, "Exact early specular paths"). No random draw and no float operation of
// a ray depends on N, so N = 0 gives the same groups, bit for bit, as before the feature.
#pragma once

#include <tbb/task_arena.h>

#include <array>
#include <cstdint>
#include <functional>
#include <glm/vec3.hpp>
#include <memory>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "common/bands.h"
#include "common/random.h"
#include "engine/frame_groups.h"
#include "engine/frame_hits.h"
#include "engine/frame_inputs.h"
#include "engine/geometry.h"
#include "engine/patch.h"
#include "engine/specular_paths.h"
#include "engine/sphere_grid.h"
#include "engine/trace_request.h"
#include "engine/tracer.h"
#include "engine/transmission.h"
#include "scene/directivity.h"
#include "scene/scene.h"

namespace dpc {

class ReflectionScattering;  // engine/reflection_scattering.h

/// The air's energy attenuation per metre and band (ISO 9613-1, 1/m) the settings ask for:
/// 0 when settings.airAbsorption is off. Any thread.
Bands propagationAirAttenuation(const PropagationSettings& settings);

class Propagator {
 public:
  /// Above this many receiver spheres a frame's segments find theirs through a SphereGrid
  /// (engine/sphere_grid.h) instead of testing each; up to it, the plain loop (cheaper for few).
  static constexpr size_t kMaxLinearSpheres = 8;
  /// A ray's carried-band mask with every band (RayState::bands).
  static constexpr uint8_t kAllBands = uint8_t((1u << kNumBands) - 1);
  /// Survival probability of a ray that Russian roulette tests.
  static constexpr float kRouletteSurvival = 0.1f;

  /// What is fixed for the propagator's life besides the settings.
  struct Options {
    /// Scalar or packet queries (same physics, same random streams).
    TraceMode traceMode = kDefaultTraceMode;
    /// Per triangle, its coplanar face (CoplanarFaces::faces): the specular sequences record
    /// faces, as the exact paths are found over faces. Empty: triangles. Must outlive the
    /// propagator.
    std::span<const uint32_t> specularFaces;
    /// The path identifier rule (engine/patch.h); none: PathKeyRule::forRoom of the
    /// geometry's bounding box and surface area with 1 ms energy bins.
    std::optional<PathKeyRule> keyRule;
    /// Free-standing faces' reflection-based scattering (engine/reflection_scattering.h);
    /// none: every reflection scatters with its material's coefficient alone. Must outlive
    /// the propagator.
    const ReflectionScattering* reflectionScattering = nullptr;
  };

  /// geometry (patches, materials), tracer (ray queries over the same triangles) and settings
  /// (max order, air, roulette, exact order, threads, speed of sound) must outlive the
  /// Propagator; the rays, seed and everything else that varies per frame come with each
  /// TraceRequest.
  Propagator(const Geometry& geometry, const Tracer& tracer, const PropagationSettings& settings,
             const Options& options);
  Propagator(const Geometry& geometry, const Tracer& tracer, const PropagationSettings& settings)
      : Propagator(geometry, tracer, settings, Options{}) {}
  ~Propagator();

  /// Traces request.rays rays from request.origin, tests every segment against every sphere
  /// of request.receivers and appends receiver l's hits in ray order to *hits[l]
  /// (hits.size() == receivers.size(); the caller clears them), with l's id finished into the
  /// path identifier (thesis §3.2.2: the path identifier carries the listener) and each hit of
  /// an all-specular run of order <= exactOrder() tagged with its sequence (FrameHits). Tracer
  /// work (the segments) does not depend on the receivers, only the ray-sphere tests do; the
  /// random streams do not depend on them either, so receiver l's hits equal, bit for bit,
  /// those of tracing it alone (up to the id in the keys). candidates (optional, used when
  /// exactOrder() > 0): receives, in ray order, every all-specular triangle sequence of order
  /// 1..exactOrder() the rays followed (the caller clears it). Propagation thread; allocation
  /// as in the file comment.
  TraceStats traceFrame(const TraceRequest& request, std::span<FrameHits* const> hits,
                        SpecularCandidates* candidates = nullptr);
  /// The same grouped by path identifier into *groups[l] (the caller clears them), every
  /// exact specular hit left out (FrameHits::groupInto with no exact paths): for callers that
  /// do not keep exact paths' caches.
  TraceStats traceFrame(const TraceRequest& request, std::span<FrameGroups* const> groups,
                        SpecularCandidates* candidates = nullptr);
  /// One receiver (request.receivers.size() == 1) into `groups`.
  TraceStats traceFrame(const TraceRequest& request, FrameGroups& groups);

  /// Image-source candidates without a full trace: request.rays rays leave request.origin (a
  /// listener) in uniform directions and reflect in the mirror direction only, up to
  /// exactOrder() reflections, testing no sphere; every face sequence they follow and its
  /// prefixes go into `candidates` (the caller clears it) in source-first order (reversed, as
  /// tracing from the listeners reverses them). A sequence an exact path follows is proposed
  /// whenever a ray leaves the listener toward its last reflection point, as a full trace from
  /// either end proposes it, but a ray costs at most exactOrder() segments and serves every
  /// source. For sources whose rays are not traced (played from a bake). Streams from (seed,
  /// frame, emitter) salted apart from traceFrame's; bit-identical for any thread count.
  /// Returns the rays and segments traced (no listener hits). No allocation after the first
  /// frame of as many rays.
  TraceStats proposeSpecular(const TraceRequest& request, SpecularCandidates& candidates);

  /// Order N of the exact specular paths: settings.exactOrder clamped to [0, kMaxExactOrder]
  /// and to maxOrder (a path the rays cannot follow is not removed from them either).
  int exactOrder() const { return exactOrder_; }

  /// The direct sound from a source of the given pattern and forward axis (unit vector,
  /// world; omni by default) to the listener centre: blocked by an opaque surface, attenuated
  /// by the transmittance of every transmitting surface it crosses (DirectSound::crossings),
  /// weighted by the pattern toward the listener. The distance is clamped to at least R/2,
  /// where 1/(4 pi r^2) equals what rays crossing the sphere would report (1/(pi R^2)).
  /// Thread-safe, for per-pair work in parallel.
  DirectSound directSound(const glm::vec3& source, const ListenerSphere& listener,
                          const Directivity& directivity = {},
                          const glm::vec3& forward = {1.f, 0.f, 0.f}) const;

  /// The straight path from source over toListener (length dist, metres) through the
  /// geometry: an occlusion query when no material transmits, else engine/transmission.h's walk.
  PathTransmission directTransmission(const glm::vec3& source, const glm::vec3& toListener,
                                      float dist) const;

  TraceMode traceMode() const { return traceMode_; }
  const Bands& airAttenuationPerMetre() const { return airPerMetre_; }

  /// Runs f(i) for i in [0, n) on the tracing threads (the same task arena as traceFrame), in
  /// any order and concurrently; returns when all are done. For per-listener work after a
  /// trace (each i must touch only its own data). Propagation thread.
  void forEachParallel(size_t n, const std::function<void(size_t)>& f);
  /// The tracing threads: how many f(i) of forEachParallel may run at once.
  int concurrency() const;
  const PropagationSettings& settings() const { return settings_; }
  const PathKeyRule& pathKeyRule() const { return keyRule_; }

 private:
  /// One ray's state between queries.
  struct RayState {
    Rng rng{0, 0};
    glm::vec3 org{0.f}, dir{0.f};
    Bands energy{1.f};
    glm::vec3 firstDir{0.f};  ///< direction of the first segment (tracing from listeners)
    float travelled = 0.f;
    float coherentFrom = 0.f;  ///< travelled at the last diffuse reflection: the wave's origin
    PathKey path;
    int order = 0;
    int band = 0;  ///< band whose scattering coefficient steers reflections
    uint8_t bands = kAllBands;  ///< the bands it carries (bit b: band b); `band` the lowest
    /// Leading reflections that were all specular, at most exactOrder_ (== order while the
    /// path is all specular and short enough to be an exact path), and their triangles.
    int specularRun = 0;
    std::array<uint32_t, kMaxExactOrder> specular{};
    /// True when this ray's listener hits belong to an exact specular path (left out).
    bool exactSpecular() const { return order > 0 && specularRun == order; }
  };
  /// Hits with their receiver and exact specular tag (FrameHits::add), in parallel arrays.
  struct HitList {
    std::vector<PathHit> hits;
    std::vector<uint32_t> receiver;
    std::vector<uint64_t> sequence;
    std::vector<uint8_t> exact;
    void clear() {
      hits.clear(), receiver.clear(), sequence.clear(), exact.clear();
    }
    void resize(size_t n) {
      hits.resize(n), receiver.resize(n), sequence.resize(n), exact.resize(n);
    }
    void copy(size_t from, const HitList& other, size_t to) {
      hits[to] = other.hits[from], receiver[to] = other.receiver[from];
      sequence[to] = other.sequence[from], exact[to] = other.exact[from];
    }
  };
  struct Chunk {
    HitList ordered;                             ///< the chunk's hits in ray order
    std::vector<SpecularSequence> specularRuns;  ///< per ended ray with a run: its sequence
    uint64_t segments = 0;
    Bands maxOrderEnergy{0.f};  ///< TraceStats::maxOrderEnergy of the chunk's rays
    // Packet mode scratch: hits in completion order with their ray (offset in the chunk),
    // and the per-ray counts/offsets of the counting sort back into ray order.
    HitList unordered;
    std::vector<uint32_t> rayOf;
    std::vector<uint32_t> offsets;
    /// Moves `unordered` into `ordered` in ray order (count rays from the chunk's first).
    void sortByRay(uint32_t count);
  };
  /// One pass of traceFrame: its request and the seed of its random streams.
  struct Pass {
    const TraceRequest& request;
    uint64_t frameSeed;
  };
  void startRay(const Pass& pass, uint32_t rayIndex, RayState& ray) const;
  /// Applies one query's answer (surface hit or miss) to the ray: receiver tests (append to
  /// `out`, in receiver order), then reflection. Returns false when the ray ends; a ray the
  /// order bound ends adds the energy it still carries to `cut`.
  bool advance(const TraceRequest& rq, RayState& ray, bool surface, const SurfaceHit& hit,
               HitList& out, Bands& cut) const;
  /// The segment of `ray` up to segEnd (m) against every receiver sphere: appends a hit per
  /// sphere it crosses (with its receiver index): in receiver order, or the sphere hierarchy's
  /// order above kMaxLinearSpheres.
  void testListeners(const TraceRequest& rq, const RayState& ray, float segEnd,
                     HitList& out) const;
  /// The segment against receiver l: appends its hit when it crosses.
  void testSphere(const TraceRequest& rq, const RayState& ray, float segEnd, uint32_t l,
                  HitList& out) const;
  /// Rebuilds sphereGrid_ over `receivers` when there are more than kMaxLinearSpheres.
  void prepareSpheres(std::span<const ListenerSphere> receivers);
  /// The ray's leading specular run (k first reflections) as a source-first sequence: as
  /// recorded, or reversed when tracing from a listener.
  static SpecularSequence sourceFirstRun(const RayState& ray, uint32_t k, bool fromListener);
  /// One sphere crossing of `ray` (b: distance along the segment to the point of closest
  /// approach): the PathHit to receiver l.
  PathHit makeHit(const TraceRequest& rq, const RayState& ray, uint32_t l, float b,
                  float segEnd) const;
  /// Whether a ray's energy, attenuated by the weakest band's air absorption over its length,
  /// has fallen below the Russian roulette threshold.
  bool belowRouletteThreshold(const RayState& ray) const;
  /// Reflects `ray` at `hit`: patch into the path identifier (up to the identifier's full
  /// order), reflectance, Russian roulette, diffuse or specular direction. Returns false when
  /// roulette ends the ray.
  bool reflect(RayState& ray, const SurfaceHit& hit) const;
  /// Whether the reflection at `org` (lit normal n, mirror direction `mirrored`) scatters:
  /// the material's coefficient, off a free-standing face ReflectionScattering::scatters.
  bool scatters(RayState& ray, const SurfaceHit& hit, const glm::vec3& org, const glm::vec3& n,
                const glm::vec3& mirrored) const;
  /// The face recorded in specular sequences for triangle t (Options::specularFaces).
  uint32_t faceOf(uint32_t t) const { return t < faceOf_.size() ? faceOf_[t] : t; }
  /// Appends the ended ray's leading specular sequence, if any, to chunk.specularRuns.
  void noteSpecularRun(const RayState& ray, Chunk& chunk) const;
  /// Adds the chunks' specular sequences and all their prefixes to candidates, each reversed
  /// into source-first order when listenerFirst (recorded from a listener).
  void collectCandidates(uint32_t chunkCount, SpecularCandidates& candidates,
                         bool listenerFirst) const;
  /// One proposeSpecular ray: mirror reflections from `from` up to exactOrder_, its face
  /// sequence into chunk.specularRuns, its segments counted.
  void mirrorRun(uint64_t frameSeed, uint32_t rayIndex, const glm::vec3& from, Chunk& chunk) const;
  void traceRay(const Pass& pass, uint32_t rayIndex, Chunk& chunk) const;
  void traceChunkPacket(const Pass& pass, uint32_t firstRay, uint32_t endRay, Chunk& chunk) const;
  /// The chunks of a frame of `rays` rays (grown as needed): their count and rays per chunk.
  std::pair<uint32_t, uint32_t> chunksFor(int rays);

  const Geometry& geometry_;
  const Tracer& tracer_;
  const PropagationSettings& settings_;
  Bands airPerMetre_{0.f};
  float minAir_ = 0.f;   ///< smallest band air attenuation, 1/m (roulette's upper bound)
  PathKeyRule keyRule_;  ///< order-adaptive path identifier (engine/patch.h)
  std::span<const uint32_t> faceOf_;  ///< Options::specularFaces
  const ReflectionScattering* reflectionScattering_ = nullptr;  ///< Options::reflectionScattering
  SphereGrid sphereGrid_;             ///< the frame's spheres, above kMaxLinearSpheres
  std::vector<glm::vec4> sphereBoxes_;  ///< prepareSpheres' scratch
  int exactOrder_ = 0;                  ///< exactOrder()
  TraceMode traceMode_ = kDefaultTraceMode;
  std::unique_ptr<tbb::task_arena> arena_;
  std::vector<Chunk> chunks_;
  std::vector<FrameHits> scratchHits_;  ///< the grouping traceFrame's, per receiver
  std::vector<FrameHits*> scratchPtrs_;
};

}  // namespace dpc
