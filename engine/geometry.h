// Acoustic geometry: the scene's triangles in an Embree 3 BVH, with per-triangle material and
// patch subdivision.
//
// EmbreeDevice and the scene handle are owned here and released here only (RAII), following
// the Embree tutorials: the device error callback is registered once at creation and records
// the first error, which build steps turn into a std::runtime_error.
// Construction: control/propagation thread; allocates; throws std::runtime_error on an
// Embree error and std::invalid_argument on inconsistent input (the scene loader validates
// user input first). Queries (intersect, intersect16, occluded): any number of threads at once;
// no allocation; no errors.
#pragma once

#include <embree3/rtcore.h>

#include <array>
#include <cstdint>
#include <glm/vec3.hpp>
#include <string>
#include <vector>

#include "common/bands.h"
#include "engine/patch.h"
#include "scene/scene.h"

namespace dpc {

/// Owns an RTCDevice. Not copyable.
class EmbreeDevice {
 public:
  EmbreeDevice();
  ~EmbreeDevice();
  EmbreeDevice(const EmbreeDevice&) = delete;
  EmbreeDevice& operator=(const EmbreeDevice&) = delete;
  RTCDevice get() const { return device_; }
  /// Throws std::runtime_error("Embree: <what>, during <step>") if an error was recorded.
  void throwIfError(const char* step);

 private:
  static void onError(void* self, RTCError code, const char* str);
  RTCDevice device_ = nullptr;
  RTCError firstError_ = RTC_ERROR_NONE;
  std::string firstMessage_;
};

/// Result of a closest-hit query. t in metres along a unit direction.
struct SurfaceHit {
  float t = 0.f;
  uint32_t triangle = 0;
  std::array<float, 3> barycentric{};  ///< (1-u-v, u, v) for the triangle's vertices 0, 1, 2
  glm::vec3 normal{0.f};               ///< unit geometric normal, winding-order side
};

/// Up to 16 rays for one packet query (Geometry::intersect16). Lane i is traced only when
/// active[i]; the other lanes' org/dir are ignored. dir must be unit length. Plain data, no
/// allocation.
struct RayPacket16 {
  static constexpr int kSize = 16;
  std::array<bool, kSize> active{};
  std::array<glm::vec3, kSize> org{};
  std::array<glm::vec3, kSize> dir{};
};

/// Result of a packet query: found[i] is false for inactive lanes and for misses; hit[i] is
/// meaningful only where found[i].
struct PacketHits16 {
  std::array<bool, RayPacket16::kSize> found{};
  std::array<SurfaceHit, RayPacket16::kSize> hit{};
};

/// Triangle numbering: the static mesh's triangles come first (0 .. n-1), then each moving
/// object's in scene order. A triangle's number and its patches (defined on the object's own
/// mesh, in local coordinates) do not change when the object moves, so path identifiers and the
/// cache's grouping survive motion (docs/dynamic.md).
class Geometry {
 public:
  /// mesh: triangles and per-triangle material indices into materials; patchSize: lambda in
  /// metres (> 0). objects: moving rigid objects, each its own BVH built here once and placed
  /// in the top-level scene as an Embree instance (RTC_GEOMETRY_TYPE_INSTANCE), initially at
  /// its first keyframe's pose. Without objects the mesh is traced directly (one level).
  Geometry(const Mesh& mesh, const std::vector<Material>& materials, float patchSize,
           const std::vector<ObjectDesc>& objects = {});
  ~Geometry();
  Geometry(const Geometry&) = delete;
  Geometry& operator=(const Geometry&) = delete;

  /// Closest hit of the ray org + t*dir, t in (tnear, tfar); dir must be unit length.
  /// Returns false on a miss.
  bool intersect(const glm::vec3& org, const glm::vec3& dir, float tnear, float tfar,
                 SurfaceHit& hit) const;
  /// Closest hits of the active lanes of `rays`, t in (tnear, tfar), in one rtcIntersect16
  /// call (Embree's hybrid packet traversal, flagged incoherent: the lanes are independent
  /// paths). Each lane's answer is the same closest hit intersect() finds, up to the
  /// floating-point rounding of the packet kernels (the hit triangle may differ where a ray
  /// grazes a shared edge). Inactive lanes report found = false.
  void intersect16(const RayPacket16& rays, float tnear, float tfar, PacketHits16& hits) const;
  /// True if anything blocks the segment org + t*dir, t in (tnear, tfar).
  bool occluded(const glm::vec3& org, const glm::vec3& dir, float tnear, float tfar) const;

  /// Places object k (index into the constructor's objects) at `pose`: sets its instance
  /// transform. Takes effect at commitPoses(). Propagation thread, between frames, never while
  /// a query runs; no allocation.
  void setObjectPose(size_t object, const Pose& pose);
  /// Rebuilds the top-level BVH over the instances (cheap: one node per object, no triangle
  /// is rebuilt). Throws std::runtime_error on an Embree error. Propagation thread.
  void commitPoses();
  size_t objectCount() const { return objects_.size(); }

  uint32_t triangleCount() const { return uint32_t(patching_.size()); }
  const TrianglePatching& patching(uint32_t tri) const { return patching_[tri]; }
  /// Energy reflection factor (1 - absorption) per band of triangle tri's material.
  const Bands& reflectance(uint32_t tri) const { return reflectance_[materialOf_[tri]]; }
  /// Scattering coefficient per octave band of triangle tri's material (ISO 17497-1).
  const Bands& scattering(uint32_t tri) const { return scattering_[materialOf_[tri]]; }
  /// True if some material's scattering coefficient differs between octave bands; the
  /// tracer then gives each ray one band (Propagator, docs/design.md).
  bool scatteringVariesWithBand() const { return scatteringVariesWithBand_; }
  uint32_t materialOf(uint32_t tri) const { return materialOf_[tri]; }

  /// Axis-aligned bounds of the mesh, metres.
  glm::vec3 boundsMin() const { return boundsMin_; }
  glm::vec3 boundsMax() const { return boundsMax_; }
  /// Total surface area, m^2.
  double surfaceArea() const { return surfaceArea_; }
  /// Bytes of per-triangle data held here (patching, material index), not counting Embree.
  size_t bytesPerTriangle() const { return sizeof(TrianglePatching) + sizeof(uint32_t); }

 private:
  /// One instanced mesh: its BVH, its instance in the top-level scene, its first triangle's
  /// global number and its current rotation (hit normals come back in local coordinates).
  struct Instance {
    RTCScene scene = nullptr;
    RTCGeometry instance = nullptr;
    uint32_t firstTriangle = 0;
    glm::quat rotation{1.f, 0.f, 0.f, 0.f};
  };
  /// Adds mesh's triangles to the per-triangle tables and returns its Embree triangle geometry.
  RTCGeometry addTriangles(const Mesh& mesh, const std::vector<Material>& materials,
                           float patchSize, bool bounds);
  /// Global triangle number and world normal from an Embree hit.
  void resolveHit(unsigned instID, unsigned primID, const glm::vec3& ng, SurfaceHit& hit) const;

  EmbreeDevice device_;
  RTCScene scene_ = nullptr;
  /// Empty without objects; else [0] is the static mesh (identity), [1 + k] object k.
  std::vector<Instance> instances_;
  std::vector<Instance*> objects_;
  std::vector<TrianglePatching> patching_;
  std::vector<uint32_t> materialOf_;
  std::vector<Bands> reflectance_;
  std::vector<Bands> scattering_;
  bool scatteringVariesWithBand_ = false;
  glm::vec3 boundsMin_{0.f}, boundsMax_{0.f};
  double surfaceArea_ = 0.0;
};

}  // namespace dpc
