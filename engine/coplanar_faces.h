// Coplanar faces: the triangles of a mesh grouped into the flat polygons they tessellate, for
// the exact specular paths (engine/specular_paths.h). A specular reflection happens on a plane,
// not on a triangle: a wall cut into triangles reflects one image source, so a path whose
// reflection point lies in a neighbouring triangle of the same wall is the same path. Image
// sources over faces find each such path once, wherever on the wall the rays that proposed it
// struck, and a ray's listener hit is matched to the exact path of its face sequence.
//
// Two triangles share a face when they share an edge (welded vertices, scene/scene.h
// weldedVertexIds), lie in one plane (normals within kCoplanarCos, plane offsets within
// kCoplanarMetres) and have the same material; faces are the connected groups of that
// relation. Each mesh (the static mesh, then each object) is grouped on its own, in
// Geometry's triangle numbering (static mesh first, then objects).
//
// Construction: any thread; allocates O(triangles); no errors (a degenerate triangle is a face
// of its own).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "scene/scene.h"

namespace dpc {

class CoplanarFaces {
 public:
  /// Normals closer than this (cosine) count as parallel: 0.01 degrees.
  static constexpr double kCoplanarCos = 0.99999998;
  /// Plane offsets within this many metres count as one plane.
  static constexpr double kCoplanarMetres = 1e-5;

  /// meshes: the static mesh, then each object's mesh in its local frame (coplanarity does not
  /// change under a rigid motion).
  explicit CoplanarFaces(const std::vector<const Mesh*>& meshes);

  /// The face of triangle t: the smallest triangle number in it (t itself when alone, or when
  /// t is out of range).
  uint32_t faceOf(uint32_t t) const { return t < face_.size() ? face_[t] : t; }
  /// The triangles of face f (f a faceOf value), f first.
  std::span<const uint32_t> triangles(uint32_t f) const;
  /// The per-triangle face numbers (faceOf), for callers that keep a span.
  const std::vector<uint32_t>& faces() const { return face_; }

 private:
  /// Groups one mesh whose first triangle is number `first`.
  void groupMesh(const Mesh& mesh, uint32_t first);
  uint32_t find(uint32_t t);

  std::vector<uint32_t> face_;    ///< per triangle, its face (after grouping)
  std::vector<uint32_t> parent_;  ///< union-find, during construction
  std::vector<uint32_t> start_;   ///< per triangle t: offset of face t's list in members_
  std::vector<uint32_t> members_;
};

}  // namespace dpc
