// Which parts of a candidate edge another surface seals. An edge lying in another triangle (a
// partition's rim along the floor, a box standing on it) has no wedge of air around it: it does
// not diffract. A mesh with T-junctions (an exporter's wall strip running on past a doorway,
// whose lintel is then one triangle edge as long as the wall, the strips beside the doorway
// meeting it at vertices of their own) has edges sealed over part of their length only: the
// part of the strip's edge that no other triangle holds is the doorway's lintel, and only that
// part diffracts. Where a face in another plane meets a sheet's rim along a side without
// sharing its corners (a thick wall's reveal written with T-junctions), the two make a wedge
// over that span: one edge with both faces, laid once (by the rim whose face comes first in
// the mesh), as a welded mesh has it.
//
// Internal to the engine (diffraction_edges). Load time, any thread; construction allocates
// (a uniform grid of the triangles, O(n log n)); no errors (degenerate triangles seal nothing).
#pragma once

#include <array>
#include <cstdint>
#include <glm/vec3.hpp>
#include <vector>

#include "engine/diffraction.h"
#include "scene/scene.h"

namespace dpc {

/// The mesh's triangles, found by where they lie: a triangle can hold part of an edge only if
/// its bounding box, grown by the tolerance, holds a point of the edge, so each edge is tested
/// against the triangles registered in the cells it passes through (a uniform grid, cells
/// found by sorting (cell, triangle) pairs: O(n log n) for n triangles) plus the few
/// triangles too large for the grid (walls, floors spanning more than kMaxCellsPerTriangle
/// cells), instead of against every triangle.
class SealingSurfaces {
 public:
  explicit SealingSurfaces(const Mesh& mesh);

  /// Appends to `out` the parts of `e` that stay open, each an edge of its own with e's faces
  /// and at least kMinPart long, its ends at the corners that cut it: e less the spans that
  /// other triangles' sides lying along its line cover (sideAlong), a fold's span as a wedge
  /// of e's face and the fold's when e's face comes first in the mesh (ownTriangle, the
  /// smallest of its triangles, against the fold's; `surfaces` per triangle its flat surface);
  /// nothing when a triangle holds its midpoint otherwise than at a side (a partition's rim
  /// lying on the floor: sealed whole); e itself when no triangle holds any of it. Allocates
  /// its scratch.
  void appendOpenParts(const DiffractionEdge& e, uint32_t ownTriangle,
                       const std::vector<uint32_t>& surfaces,
                       std::vector<DiffractionEdge>& out) const;

  static constexpr float kTol = 1e-3f;      ///< m: how far off a triangle's plane still lies in it
  static constexpr float kMinPart = 2e-3f;  ///< m: shorter open parts are dropped

 private:
  struct CellEntry {
    uint64_t key;
    uint32_t triangle;
  };
  static constexpr int64_t kMaxCellsPerTriangle = 64;
  static constexpr int64_t kMaxCellsPerAxis = int64_t(1) << 20;  // 21 bits of a key each

  void growBoxes();
  void chooseCells();
  void registerTriangles();
  std::array<int64_t, 3> cellOf(const glm::vec3& p) const;
  static uint64_t keyOf(const std::array<int64_t, 3>& c);
  /// The triangles registered in the cells the edge passes through, and the large ones;
  /// ascending, without repeats.
  std::vector<uint32_t> trianglesAlong(const DiffractionEdge& e) const;
  /// Whether triangle t (not one of the edge's own faces, both ends its corners) holds the
  /// edge's midpoint, within kTol of its plane and sides: the edge is sealed whole (a
  /// partition's rim along the floor).
  bool holdsMidpoint(uint32_t t, const DiffractionEdge& e) const;
  /// A span of the edge that a triangle's side covers: [lo, hi] m along it from e.a, and the
  /// side's corners at its ends (the edge's own ends where the side runs past them).
  struct HeldSpan {
    float lo = 0.f, hi = 0.f;
    glm::vec3 loCorner{0.f}, hiCorner{0.f};
    uint32_t triangle = 0;  ///< the triangle whose side it is
    glm::vec3 inward{0.f};  ///< unit, in that triangle's plane, from the line into it
    bool fold = false;      ///< a face in another plane meeting a sheet's rim: a wedge there
  };
  /// A stretch of the edge between cuts: [lo, hi] m along it, its ends at the cutting corners;
  /// fold -1 open, -2 sealed, else the index of the fold's span.
  struct Piece {
    glm::vec3 a{0.f}, b{0.f};
    float lo = 0.f, hi = 0.f;
    int fold = -1;
  };
  /// The edge cut at every span's ends, each stretch classed by the spans over it (sealed
  /// where any surface runs on past it, else a fold where a fold meets it, else open), runs of
  /// one class joined.
  std::vector<Piece> pieces(const DiffractionEdge& e, std::vector<HeldSpan> held) const;
  /// The wedge a sheet's rim e makes with the fold's face: e's face 0, the fold's as face 1.
  DiffractionEdge foldEdge(const DiffractionEdge& e, const HeldSpan& fold,
                           const std::vector<uint32_t>& surfaces) const;

  /// Whether a side of triangle t (not one of the edge's own faces) runs along the edge's line
  /// (both its corners within kTol of it) for more than kMinPart: where a surface runs on past
  /// the edge (a T-junction: sealed), or, for a sheet's rim, a face in another plane meets it
  /// there without sharing its corners (a fold: the two make a wedge).
  bool sideAlong(uint32_t t, const DiffractionEdge& e, HeldSpan& span) const;

  const Mesh& mesh_;
  std::vector<glm::vec3> lo_, hi_;  ///< grown boxes, per triangle
  glm::vec3 origin_{0.f}, top_{0.f};
  float cell_ = 1.f;              ///< cell size, m
  std::vector<CellEntry> cells_;  ///< sorted by key
  std::vector<uint32_t> large_;   ///< triangles spanning more than kMaxCellsPerTriangle cells
};

}  // namespace dpc
