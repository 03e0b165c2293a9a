// Exact early specular paths: ray-guided image sources.
//
// The image-source method (J. B. Allen & D. A. Berkley, "Image method for efficiently
// simulating small-room acoustics", JASA 65(4), 1979) places every specular reflection path
// exactly, but enumerating all triangle sequences grows as (triangles)^order. Ray-guided image
// sources (M. Vorländer, "Auralization", Springer 2008, on hybrid ray tracing / image-source
// models) test only the triangle sequences that the traced rays actually followed: a ray whose
// first k reflections all chose the specular lobe proposes T1..Tk (and each prefix) as a
// candidate; the image construction below then decides, for each listener, whether the path
// exists and where it lies.
//
// Validation of a sequence T1..Tk for source S and listener L: S_0 = S, S_i = S_{i-1} mirrored
// in the plane of T_i. Backwards from P_{k+1} = L, P_i is where the segment P_{i+1} -> S_i
// crosses the plane of T_i; the path exists when every crossing lies strictly between its ends
// (so P_{i+1} and S_{i-1} are on the same, reflecting side of T_i), every P_i lies inside T_i,
// and no segment S -> P_1 -> ... -> P_k -> L is blocked (Tracer::occluded, so moving objects
// block in their current pose) nor passes through a gap a few centimetres wide (a closed door's
// clearance; SpecularScene::inGap). Its length is |L - S_k|. A gap that narrow is far inside
// the path's first Fresnel zone (sqrt(lambda d) is 0.2 m at 8 kHz over 1 m), so the image
// construction, which assumes that zone free, would pass the whole image through it: a closed
// door with 5 mm gaps read within 2 dB of the open doorway in total energy. What passes there is
// the slit's (engine/diffraction.h, for the direct sound).
//
// Energy of a valid path (intensity relative to source power, 1/m^2, DirectSound's scale):
//   I_b = prod_i (1 - alpha_b(T_i)) (1 - s_b(T_i)) * K_b * exp(-m_b d) / (4 pi d^2),
// m_b the ISO 9613-1 air attenuation, d the path length (the spreading clamped at R/2 as
// DirectSound does), K_b the share of the image source's field that faces standing free and
// smaller than the first Fresnel zone reflect (a door leaf, a thick doorway's reveal): at first
// order the Kirchhoff integral's (engine/small_reflectors.h), from the second the product of the
// rays' Rindel shares (engine/reflection_scattering.h); 1 otherwise. The factor (1 - s) K per
// reflection is the probability that a ray takes the specular lobe (docs/design.md, "Reflection
// direction"; at first order K the rays' own): the propagator keeps every listener hit of an
// all-specular path of order <= N out of the energy response, whose expectation is this I_b, so
// nothing is counted twice (docs/estimators.md, "Exact early specular paths"). A directional
// source weights I_b toward P_1, where the path leaves it (SpecularPathCache::weightBySource).
//
// Persistence across frames: engine/specular_path_cache.h.
//
// Threads: propagation thread. SpecularScene::validate and SpecularPathCache::update of
// different pairs may run concurrently (they only read the scene and the tracer); poses change
// between frames. Allocation: at construction, and as a pair's tables grow toward their
// capacities on the propagation thread. No errors (invalid input gives no paths).
#pragma once

#include <tsl/robin_map.h>
#include <tsl/robin_set.h>

#include <array>
#include <cstdint>
#include <glm/vec3.hpp>
#include <vector>

#include "common/bands.h"
#include "engine/coplanar_faces.h"
#include "engine/energy_response.h"
#include "engine/geometry.h"
#include "engine/small_reflectors.h"
#include "engine/tracer.h"
#include "scene/directivity.h"
#include "scene/scene.h"

namespace dpc {

class ReflectionScattering;  // engine/reflection_scattering.h

/// The faces T1..Tk of an all-specular path (CoplanarFaces::faceOf of the triangles struck:
/// the smallest triangle number of each coplanar face), k = order in 1..kMaxExactOrder;
/// entries past `order` are 0. Triangle numbers are Geometry's (static mesh first, then
/// objects).
struct SpecularSequence {
  std::array<uint32_t, kMaxExactOrder> triangles{};
  uint32_t order = 0;

  /// Stable 64-bit identifier of the sequence: the same in every frame and for every source
  /// and listener (collisions about 2^-64 per pair of sequences, as path identifiers).
  uint64_t key() const;
  /// The first k triangles (1 <= k <= order).
  SpecularSequence prefix(uint32_t k) const;
};

/// One exact specular path from a source to a listener in one frame.
struct SpecularPath {
  uint64_t key = 0;           ///< SpecularSequence::key() of its triangles: stable across frames
  uint32_t order = 0;         ///< reflections k, 1..kMaxExactOrder
  float length = 0.f;         ///< metres, |L - S_k|
  double delaySeconds = 0.0;  ///< length / c
  Bands intensity{0.f};       ///< 1/m^2 relative to source power, per octave band (formula above)
  glm::vec3 direction{0.f};   ///< unit vector from the listener toward the last reflection point
  std::array<uint32_t, kMaxExactOrder> triangles{};  ///< faces T1..Tk (SpecularSequence)
  std::array<glm::vec3, kMaxExactOrder> points{};    ///< reflection points P1..Pk, metres
};

/// Adds every path's intensity at its delay to `response` (and, when not null, with its
/// arrival direction to `directional`): the energy response the estimators would have given
/// with exact_order 0, up to Monte Carlo error, for consumers that want one response.
/// Propagation thread; no allocation.
void addSpecularPaths(const std::vector<SpecularPath>& paths, EnergyResponse& response,
                      ArrivalSink* directional = nullptr);

/// The unique sequences the rays of one source proposed in one frame, in insertion order.
/// Capacity fixed at construction; insertions beyond it are counted in overflow().
class SpecularCandidates {
 public:
  /// Default capacity: every prefix of 4096 rays' runs at order 3 still fits five times over
  /// (about 3 MB reserved, once per simulation).
  static constexpr size_t kDefaultCapacity = 1 << 16;
  explicit SpecularCandidates(size_t capacity = kDefaultCapacity);
  void clear();
  /// Adds the sequence unless present; false (and counted) when full.
  bool insert(const SpecularSequence& sequence);
  bool contains(uint64_t key) const { return index_.find(key) != index_.end(); }
  const std::vector<SpecularSequence>& sequences() const { return sequences_; }
  /// Sequences refused since the last clear() because the set was full.
  uint64_t overflow() const { return overflow_; }

 private:
  size_t capacity_;
  std::vector<SpecularSequence> sequences_;
  tsl::robin_map<uint64_t, uint32_t> index_;
  uint64_t overflow_ = 0;
};

/// A face's plane: n . x = d for its points x (n a unit normal, metres).
struct FacePlane {
  glm::dvec3 n{0.0};
  double d = 0.0;
};

/// The scene's triangles in world coordinates at the current poses, and the image-source
/// validation of a sequence.
class SpecularScene {
 public:
  /// mesh and objects as for Geometry (objects at their first keyframe's pose, as the tracer
  /// places them); geometry, tracer: the simulation's, outliving this. airPerMetre: ISO 9613-1
  /// energy attenuation per band, 1/m; speedOfSound m/s. The visibility queries keep
  /// surfaceOffset() (engine/tracer.h) clear of a reflecting surface, as the rays do.
  /// smallFaces: the same scene's free-standing faces when edge diffraction is on (its edge
  /// paths carry the rest of a small face's field; outliving this): then a path off a small
  /// free-standing face carries its share, at first order the Kirchhoff integral's
  /// (engine/small_reflectors.h), from the second on the rays' (engine/reflection_scattering.h);
  /// null: every path carries its image source's whole reflection.
  SpecularScene(const Mesh& mesh, const std::vector<ObjectDesc>& objects, const Geometry& geometry,
                const Tracer& tracer, const Bands& airPerMetre, float speedOfSound,
                const ReflectionScattering* smallFaces = nullptr);

  /// The scene's coplanar faces: sequences are over faces (CoplanarFaces::faceOf of the
  /// triangles the rays struck), and a reflection point may lie in any triangle of its face.
  const CoplanarFaces& faces() const { return faces_; }
  /// Object k's triangles follow `pose` (world = R local + position). Between frames.
  void setObjectPose(size_t object, const Pose& pose);

  /// The path of `sequence` from source to the listener sphere's centre (the spreading is
  /// clamped at radius / 2): true and `path` filled when it exists (above), false otherwise;
  /// *throughGap (when not null) true when it was refused only because it passes through a
  /// gap (inGap), whose transmission is the slit's in the direct sound (engine/slit.h).
  bool validate(const SpecularSequence& sequence, const glm::vec3& source,
                const glm::vec3& listener, float radius, SpecularPath& path,
                bool* throughGap = nullptr) const;
  /// The image S_k of `sequence` for a source at `source` (metres): the source mirrored in
  /// each face's plane in turn, whether or not the path exists for any listener; false when
  /// a face is degenerate or an image lies on the next face's plane. No allocation.
  bool imageOf(const SpecularSequence& sequence, const glm::vec3& source, glm::dvec3& image) const;

 private:
  using Triangle = WorldTriangle;
  /// The planes of the sequence's faces and the images S_0 .. S_k; false as imageOf.
  bool mirror(const SpecularSequence& sequence, const glm::dvec3& source,
              std::array<FacePlane, kMaxExactOrder>& planes,
              std::array<glm::dvec3, kMaxExactOrder + 1>& images) const;
  /// Fills path.points, returns the image S_k; false when the construction fails.
  bool construct(const SpecularSequence& sequence, const glm::dvec3& source,
                 const glm::dvec3& listener, SpecularPath& path, glm::dvec3& image) const;
  bool visible(const SpecularPath& path, const glm::vec3& source, const glm::vec3& listener) const;
  /// Whether a surface passes through the reflection point `point` between its incoming leg
  /// (from `from`) and outgoing one (to `to`): the chord between the legs kTurnChord (or a
  /// quarter of the shorter leg) from the point is blocked. One ray.
  bool turnBlocked(const glm::vec3& from, const glm::vec3& point, const glm::vec3& to) const;
  /// Metres along each leg from a reflection point to turnBlocked's chord: well above float
  /// rounding of metre coordinates, well below a surface's distance from a reflection point
  /// that a path could pass (a surface that near lies in a gap, inGap).
  static constexpr float kTurnChord = 0.005f;
  /// Whether the path passes through a gap at most 2 kChannelGapMax wide (engine/
  /// channel_path.h): a reflection point with a surface facing it that near (facedWithin), or
  /// a segment whose parallels that far to both sides, in either of two directions square to
  /// it, are blocked within kChannelDepthMax of each other along it (segmentInGap). Up to
  /// 4 (k + 1) + k rays.
  bool inGap(const SpecularPath& path, const glm::vec3& source, const glm::vec3& listener) const;
  bool facedWithin(const glm::vec3& point, uint32_t face, const glm::vec3& from) const;
  /// aFace, bFace: the faces the segment's ends reflect from (kNoFace for the source's and
  /// the listener's ends).
  bool segmentInGap(const glm::vec3& a, const glm::vec3& b, uint32_t aFace, uint32_t bFace) const;
  static constexpr uint32_t kNoFace = 0xffffffffu;
  /// Whether q (on the face's plane) lies in one of face's triangles.
  bool insideFace(const glm::dvec3& q, uint32_t face) const;

  CoplanarFaces faces_;
  /// Which faces stand free, and the share they reflect (none without edge diffraction).
  const ReflectionScattering* smallFaces_ = nullptr;
  std::vector<Triangle> world_;               ///< per triangle, current pose
  std::vector<std::vector<Triangle>> local_;  ///< per object, local coordinates
  std::vector<uint32_t> objectFirst_;         ///< per object, its first triangle number
  const Geometry& geometry_;
  const Tracer& tracer_;
  Bands airPerMetre_;
  float speedOfSound_;
};

}  // namespace dpc
