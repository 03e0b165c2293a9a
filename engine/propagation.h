// Monte Carlo sound propagation from a point source through the scene (one frame).
//
// Each frame emits N uniformly distributed rays from a source. A ray reflects up to
// max_order times: at each hit its band energy is multiplied by (1 - absorption); with
// probability `scattering` it leaves in a cosine-weighted (Lambert) direction, otherwise in
// the mirror direction. Every segment (including the one leaving the source only when
// includeDirectRays is set; the direct sound is otherwise analytic) is tested against the
// listener sphere of radius R; a crossing adds a PathHit with
//   I(omega) = energy(omega) * exp(-m(omega) r) / (pi R^2),
// r the path length to the point of closest approach to the listener's centre, m the
// ISO 9613-1 air attenuation. Dividing by N gives intensity relative to the source power on
// the scale of the direct sound 1/(4 pi r^2) (design.md, "energy convention").
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
// whatever the thread count. Allocation: per-chunk hit buffers grow to their high-water mark,
// then are reused. No errors.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <glm/vec3.hpp>
#include <tbb/task_arena.h>

#include "engine/bands.h"
#include "engine/geometry.h"
#include "engine/path_cache.h"
#include "engine/scene.h"

namespace dpc {

struct ListenerSphere {
  glm::vec3 position{0.f};  ///< metres
  float radius = 0.5f;      ///< metres, > 0
};

/// Analytic direct sound: line of sight, 1/(4 pi r^2), air absorption.
struct DirectSound {
  bool visible = false;
  float distance = 0.f;       ///< metres (clamped below at R/2: see directSound())
  float delaySeconds = 0.f;   ///< distance / c
  Bands intensity{0.f};       ///< 1/m^2 relative to source power; zero when occluded
  glm::vec3 direction{0.f};   ///< unit vector from the listener toward the source
};

struct TraceStats {
  uint64_t rays = 0;          ///< rays emitted
  uint64_t segments = 0;      ///< ray segments traced (Embree closest-hit queries)
  uint64_t listenerHits = 0;  ///< segments that crossed the listener sphere
};

class Propagator {
 public:
  /// Survival probability of a ray that Russian roulette tests.
  static constexpr float kRouletteSurvival = 0.1f;

  /// geometry must outlive the Propagator. settings: rays, max order, seed, air, threads.
  Propagator(const Geometry& geometry, const PropagationSettings& settings);
  ~Propagator();

  /// Traces settings.raysPerFrame rays from `source` and adds the listener hits, grouped by
  /// path identifier in ray order, to `groups` (which the caller clears).
  TraceStats traceFrame(uint64_t frameIndex, uint32_t sourceIndex, const glm::vec3& source,
                        const ListenerSphere& listener, FrameGroups& groups);

  /// The direct sound from source to listener centre. The distance is clamped to at least
  /// R/2, where 1/(4 pi r^2) equals what rays crossing the sphere would report (1/(pi R^2)).
  DirectSound directSound(const glm::vec3& source, const ListenerSphere& listener) const;

  /// When true, segments leaving the source also count as listener hits (for calibration
  /// against 1/(4 pi r^2); the renderer keeps the analytic direct sound instead).
  void setIncludeDirectRays(bool on) { includeDirectRays_ = on; }

  const Bands& airAttenuationPerMetre() const { return airPerMetre_; }
  const PropagationSettings& settings() const { return settings_; }
  void setRaysPerFrame(int n) { settings_.raysPerFrame = n; }

 private:
  void traceRay(uint64_t frameSeed, uint32_t sourceIndex, uint32_t rayIndex,
                const glm::vec3& source, const ListenerSphere& listener,
                std::vector<PathHit>& hits, uint64_t& segments) const;

  const Geometry& geometry_;
  PropagationSettings settings_;
  Bands airPerMetre_{0.f};
  float minAir_ = 0.f;  ///< smallest band air attenuation, 1/m (roulette's upper bound)
  float epsilon_ = 1e-4f;
  bool includeDirectRays_ = false;
  std::unique_ptr<tbb::task_arena> arena_;
  struct Chunk {
    std::vector<PathHit> hits;
    uint64_t segments = 0;
  };
  std::vector<Chunk> chunks_;
};

}  // namespace dpc
