// A uniform grid over spheres, for the ray-segment test against many receiver spheres (every
// source sphere when tracing from the listeners): a segment walks the cells it crosses
// (Amanatides & Woo, "A fast voxel traversal algorithm for ray tracing", Eurographics 1987) and
// meets only the spheres registered there, so its cost follows its length through the spheres'
// region, not their count. Receiver spheres share one radius and spread through a room (talkers
// on a floor, a market's stalls), which a grid of about kCellsPerSphere cells per sphere fits
// without a hierarchy's descent per node.
//
// Each sphere is registered in every cell its bounding box (grown by kMargin of a cell, so that
// the traversal's rounding cannot step past a cell the segment clips) overlaps. A segment is
// offered a sphere in the first cell of its walk that holds it: the cells a line crosses within
// one box of cells form one contiguous run of its walk (each axis index changes monotonically),
// so "the previous cell was outside the sphere's box of cells" marks that first cell exactly and
// no sphere is offered twice.
//
// Threads: build on one thread, then forEachCandidate from any number of threads (read only).
// Allocation: build grows its tables to the largest sizes seen, then reuses them;
// forEachCandidate never allocates. No errors.
#pragma once

#include <array>
#include <cstdint>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>
#include <span>
#include <vector>

namespace dpc {

class SphereGrid {
 public:
  /// Cells per sphere the grid aims at (its total, spread over the spheres' bounding box in
  /// proportion to its sides); at most kMaxCellsPerAxis along an axis.
  static constexpr double kCellsPerSphere = 2.0;
  static constexpr int kMaxCellsPerAxis = 256;
  /// Registration margin: a fraction of a cell's side around each sphere's box.
  static constexpr float kMargin = 1e-3f;

  /// spheres: centre (x, y, z, metres) and radius (w, metres, > 0).
  void build(std::span<const glm::vec4> spheres);
  size_t size() const { return boxes_.size(); }

  /// Calls f(index) once for every sphere whose (grown) bounding box the segment org + t dir,
  /// t in [0, segEnd] (dir unit, segEnd metres or infinity), crosses: a superset of the
  /// spheres it meets; the caller tests the sphere itself. Order: along the segment by cell.
  template <class F>
  void forEachCandidate(const glm::vec3& org, const glm::vec3& dir, float segEnd, F&& f) const {
    Walk w;
    if (!start(org, dir, segEnd, w)) return;
    for (;;) {
      const uint32_t c = cellIndex(w.cell);
      for (uint32_t k = offsets_[c]; k < offsets_[c + 1]; ++k) {
        const uint32_t s = members_[k];
        if (!w.first && inside(boxes_[s], w.previous)) continue;  // offered in an earlier cell
        f(s);
      }
      if (!advance(w)) return;
    }
  }

 private:
  using Cell = std::array<int, 3>;
  struct CellBox {
    Cell lo, hi;  ///< inclusive cell ranges per axis
  };
  /// One segment's walk: its cell, the one before, and the next boundary crossings.
  struct Walk {
    Cell cell{}, previous{}, step{};
    glm::vec3 tMax{0.f}, tDelta{0.f};
    float tEnd = 0.f;
    bool first = true;
  };
  bool start(const glm::vec3& org, const glm::vec3& dir, float segEnd, Walk& w) const;
  bool advance(Walk& w) const;
  static bool inside(const CellBox& b, const Cell& c) {
    return c[0] >= b.lo[0] && c[0] <= b.hi[0] && c[1] >= b.lo[1] && c[1] <= b.hi[1] &&
           c[2] >= b.lo[2] && c[2] <= b.hi[2];
  }
  uint32_t cellIndex(const Cell& c) const {
    return uint32_t((c[2] * cells_[1] + c[1]) * cells_[0] + c[0]);
  }
  int cellOf(float x, int axis) const;
  /// cells_, side_, inverseSide_ for a box of `extent` (m) holding `spheres` spheres.
  void fitCells(const glm::vec3& extent, size_t spheres);

  glm::vec3 lo_{0.f}, hi_{0.f}, side_{1.f}, inverseSide_{1.f};
  Cell cells_{1, 1, 1};
  std::vector<CellBox> boxes_;     ///< per sphere
  std::vector<uint32_t> offsets_;  ///< per cell, into members_ (cells + 1 entries)
  std::vector<uint32_t> members_;  ///< sphere indices, by cell
  std::vector<uint32_t> counts_;   ///< build's scratch
};

}  // namespace dpc
