// Tracer: the ray queries that propagation, diffraction, the direct sound and the setup check
// ask of the scene's triangles, and the rigid motion of its objects. engine/embree_tracer.h is
// the implementation (Embree 3); nothing above it sees a ray-tracing library.
//
// Units: metres; directions are unit vectors, t is the distance along them. Triangles are
// numbered as Geometry numbers them (the static mesh's first, then each object's in scene
// order), so a hit's triangle indexes Geometry's patch and material tables.
// Threads: the queries (intersect, occluded, single or batch) may run on any number of
// threads at once (the propagation thread and its TBB workers); they do not allocate and
// report no errors. setObjectPose and commitPoses run on the propagation thread between
// frames, never while a query runs.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <glm/vec3.hpp>
#include <limits>
#include <span>

#include "scene/scene.h"

namespace dpc {

/// Result of a closest-hit query. t in metres along a unit direction.
struct SurfaceHit {
  float t = 0.f;
  uint32_t triangle = 0;
  std::array<float, 3> barycentric{};  ///< (1-u-v, u, v) for the triangle's vertices 0, 1, 2
  glm::vec3 normal{0.f};               ///< unit geometric normal, winding-order side
};

/// Metres a ray leaving surface point p starts off the surface, and a segment ending on one
/// stops short of it, so that the next query does not find the same surface again. A hit
/// point's float rounding grows with its coordinates and with the distance t its ray
/// travelled, so the offset is relative to the larger of the two: 2^-19 of it (16 units in
/// the last place), never below kMinSurfaceOffsetM. Relative to each point, not to the
/// scene's size: a far-away triangle must not push every room's rays a metre off its walls.
/// Any thread; no allocation.
inline constexpr float kMinSurfaceOffsetM = 1e-4f;
inline float surfaceOffset(const glm::vec3& p, float t = 0.f) {
  const float m = std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z), std::abs(t)});
  return std::max(kMinSurfaceOffsetM, m * 0x1p-19f);
}

/// One ray of a query: the points org + t*dir with t in (tnear, tfar); dir unit length.
/// An inactive ray is skipped and keeps its place in a batch. Plain data.
struct TraceRay {
  glm::vec3 org{0.f};
  glm::vec3 dir{0.f};
  float tnear = 0.f;
  float tfar = std::numeric_limits<float>::infinity();
  bool active = true;
};

/// Answer of a batch closest-hit query for one ray: found is false for a miss and for an
/// inactive ray; surface is meaningful only where found.
struct TraceHit {
  bool found = false;
  SurfaceHit surface;
};

/// Which triangles a filtered query sees: accepts(self, triangle) false lets the ray pass that
/// triangle (global number, as SurfaceHit::triangle) as if it were absent. Where two coplanar
/// triangles lie at one distance, which one a plain query reports is the ray tracer's tie;
/// leaving one out decides it. accepts runs on the querying thread and must not allocate.
struct TriangleFilter {
  bool (*accepts)(const void* self, uint32_t triangle) = nullptr;
  const void* self = nullptr;
};

class Tracer {
 public:
  /// Rays the implementation traces together in a batch: rays [16 j, 16 j + 16) of a batch
  /// form one packet, each ray in its lane (a shorter last packet has idle lanes). Callers
  /// that keep rays in flight in lockstep fill batches of this size.
  static constexpr size_t kPacketSize = 16;

  virtual ~Tracer() = default;

  /// Closest hit of one ray; false on a miss (hit is then unchanged).
  virtual bool intersect(const TraceRay& ray, SurfaceHit& hit) const = 0;
  /// Closest hit of one ray among the triangles `filter` accepts (every one when
  /// filter.accepts is null); false when none.
  virtual bool intersect(const TraceRay& ray, const TriangleFilter& filter,
                         SurfaceHit& hit) const = 0;
  /// True if anything blocks the ray between tnear and tfar (any hit).
  virtual bool occluded(const TraceRay& ray) const = 0;

  /// Closest hits of a batch: hits[i] answers rays[i] (hits.size() >= rays.size()). Traced in
  /// packets of kPacketSize flagged incoherent (the rays are independent paths); each answer
  /// is the closest hit the single-ray query finds, up to the floating-point rounding of the
  /// packet kernels (the hit triangle may differ where a ray grazes a shared edge).
  virtual void intersect(std::span<const TraceRay> rays, std::span<TraceHit> hits) const = 0;
  /// Any-hit of a batch: blocked[i] answers rays[i] (false for inactive rays; blocked.size()
  /// >= rays.size()), in packets as above.
  virtual void occluded(std::span<const TraceRay> rays, std::span<bool> blocked) const = 0;

  /// Moving rigid objects (the scene's `objects`, scene order), each at its first keyframe's
  /// pose after construction.
  virtual size_t objectCount() const = 0;
  /// Places object k at `pose` (position in metres, unit rotation); takes effect at
  /// commitPoses(). Propagation thread, between frames; no allocation.
  virtual void setObjectPose(size_t object, const Pose& pose) = 0;
  /// Makes the poses set since the last commit visible to queries. Propagation thread,
  /// between frames; throws std::runtime_error if the implementation fails.
  virtual void commitPoses() = 0;
};

/// True when nothing blocks the straight segment between two points (metres). Points closer
/// than 1 mm see each other. Any thread that may query the tracer; no allocation.
inline bool lineOfSight(const Tracer& tracer, const glm::vec3& a, const glm::vec3& b) {
  const glm::vec3 d = b - a;
  const float length = std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
  if (length < 1e-3f) return true;
  return !tracer.occluded(TraceRay{a, d / length, 0.f, length});
}

}  // namespace dpc
