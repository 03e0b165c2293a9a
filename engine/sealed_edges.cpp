#include "engine/sealed_edges.h"

#include <algorithm>
#include <cmath>
#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include <glm/vector_relational.hpp>
#include <limits>
#include <numbers>
#include <utility>

namespace dpc {

namespace {

glm::vec3 unitOrZero(const glm::vec3& v) {
  const float l = glm::length(v);
  return l > 0.f ? v / l : glm::vec3(0.f);
}

}  // namespace

SealingSurfaces::SealingSurfaces(const Mesh& mesh) : mesh_(mesh) {
  growBoxes();
  chooseCells();
  registerTriangles();
}

void SealingSurfaces::growBoxes() {
  lo_.reserve(mesh_.triangles.size());
  hi_.reserve(mesh_.triangles.size());
  for (const auto& tr : mesh_.triangles) {
    const glm::vec3 p0 = mesh_.vertices[tr[0]], p1 = mesh_.vertices[tr[1]],
                    p2 = mesh_.vertices[tr[2]];
    lo_.push_back(glm::min(p0, glm::min(p1, p2)) - kTol);
    hi_.push_back(glm::max(p0, glm::max(p1, p2)) + kTol);
    origin_ = lo_.size() == 1 ? lo_.back() : glm::min(origin_, lo_.back());
    top_ = hi_.size() == 1 ? hi_.back() : glm::max(top_, hi_.back());
  }
}

/// Cubic cells twice the median triangle's largest extent, coarser if the grid would exceed
/// kMaxCellsPerAxis along an axis.
void SealingSurfaces::chooseCells() {
  if (lo_.empty()) return;
  std::vector<float> extents(lo_.size());
  for (size_t t = 0; t < lo_.size(); ++t) {
    const glm::vec3 d = hi_[t] - lo_[t];
    extents[t] = std::max(d.x, std::max(d.y, d.z));
  }
  std::nth_element(extents.begin(), extents.begin() + ptrdiff_t(extents.size() / 2), extents.end());
  const glm::vec3 span = top_ - origin_;
  const float widest = std::max(span.x, std::max(span.y, span.z));
  cell_ =
      std::max(std::max(2.f * extents[extents.size() / 2], widest / float(kMaxCellsPerAxis - 2)),
               4.f * kTol);
}

/// The grid cell holding p, each coordinate clamped to the grid: monotone in p, so the cell
/// of a point inside a grown box is one the box was registered in.
std::array<int64_t, 3> SealingSurfaces::cellOf(const glm::vec3& p) const {
  std::array<int64_t, 3> c{};
  for (int k = 0; k < 3; ++k) {
    const float f = std::floor((p[k] - origin_[k]) / cell_);
    c[size_t(k)] = std::clamp(int64_t(std::clamp(f, -1.f, float(kMaxCellsPerAxis))), int64_t(0),
                              kMaxCellsPerAxis - 1);
  }
  return c;
}

uint64_t SealingSurfaces::keyOf(const std::array<int64_t, 3>& c) {
  return uint64_t(c[0]) << 42 | uint64_t(c[1]) << 21 | uint64_t(c[2]);
}

/// Every triangle into the cells its grown box overlaps (or into large_), sorted by cell.
void SealingSurfaces::registerTriangles() {
  cells_.reserve(lo_.size() * 4);
  for (uint32_t t = 0; t < lo_.size(); ++t) {
    const auto a = cellOf(lo_[t]), b = cellOf(hi_[t]);
    if ((b[0] - a[0] + 1) * (b[1] - a[1] + 1) * (b[2] - a[2] + 1) > kMaxCellsPerTriangle) {
      large_.push_back(t);
      continue;
    }
    for (int64_t x = a[0]; x <= b[0]; ++x)
      for (int64_t y = a[1]; y <= b[1]; ++y)
        for (int64_t z = a[2]; z <= b[2]; ++z) cells_.push_back({keyOf({x, y, z}), t});
  }
  std::sort(cells_.begin(), cells_.end(), [](const CellEntry& x, const CellEntry& y) {
    return x.key != y.key ? x.key < y.key : x.triangle < y.triangle;
  });
}

std::vector<uint32_t> SealingSurfaces::trianglesAlong(const DiffractionEdge& e) const {
  // The cells the edge passes through, in order (a grid walk: J. Amanatides, A. Woo, "A fast
  // voxel traversal algorithm for ray tracing", Eurographics 1987): a triangle holding a point
  // of the edge was registered in that point's cell.
  // The walk's cells and its steps both come from the same double coordinates, so that an end
  // within rounding of a cell's side does not put the whole walk one cell off; the float
  // registration's grown boxes (kTol) cover the difference between the two.
  const glm::dvec3 ga = (glm::dvec3(e.a) - glm::dvec3(origin_)) / double(cell_);
  const glm::dvec3 d = (glm::dvec3(e.b) - glm::dvec3(origin_)) / double(cell_) - ga;
  std::array<int64_t, 3> c{}, step{};
  glm::dvec3 next(std::numeric_limits<double>::infinity()), delta(next);
  int64_t cells = 1;  // at most: one per cell side crossed, and the first
  for (int k = 0; k < 3; ++k) {
    c[size_t(k)] = int64_t(std::floor(ga[k]));
    cells += std::abs(int64_t(std::floor(ga[k] + d[k])) - c[size_t(k)]);
    if (d[k] == 0.0) continue;
    step[size_t(k)] = d[k] > 0.0 ? 1 : -1;
    delta[k] = 1.0 / std::abs(d[k]);
    next[k] = (double(c[size_t(k)]) + (d[k] > 0.0 ? 1.0 : 0.0) - ga[k]) / d[k];
  }
  std::vector<uint32_t> out(large_);
  for (int64_t i = 0; i < cells; ++i) {
    std::array<int64_t, 3> clamped{};
    for (size_t k = 0; k < 3; ++k) clamped[k] = std::clamp(c[k], int64_t(0), kMaxCellsPerAxis - 1);
    const auto cell =
        std::equal_range(cells_.begin(), cells_.end(), CellEntry{keyOf(clamped), 0},
                         [](const CellEntry& x, const CellEntry& y) { return x.key < y.key; });
    for (auto it = cell.first; it != cell.second; ++it) out.push_back(it->triangle);
    const int k = next[0] < next[1] ? (next[0] < next[2] ? 0 : 2) : (next[1] < next[2] ? 1 : 2);
    if (!(next[k] <= 1.0)) break;
    c[size_t(k)] += step[size_t(k)];
    next[k] += delta[k];
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

bool SealingSurfaces::holdsMidpoint(uint32_t t, const DiffractionEdge& e) const {
  const glm::vec3 mid = 0.5f * (e.a + e.b);
  if (glm::any(glm::lessThan(mid, lo_[t])) || glm::any(glm::greaterThan(mid, hi_[t]))) return false;
  const auto& tr = mesh_.triangles[t];
  const glm::vec3 p0 = mesh_.vertices[tr[0]], p1 = mesh_.vertices[tr[1]],
                  p2 = mesh_.vertices[tr[2]];
  const glm::vec3 nrm = unitOrZero(glm::cross(p1 - p0, p2 - p0));
  if (glm::length(nrm) == 0.f) return false;
  if (std::abs(glm::dot(e.a - p0, nrm)) > kTol || std::abs(glm::dot(e.b - p0, nrm)) > kTol)
    return false;
  auto isCorner = [&](const glm::vec3& v) { return v == p0 || v == p1 || v == p2; };
  if (isCorner(e.a) && isCorner(e.b)) return false;         // one of the edge's own faces
  const glm::vec3 q = mid - glm::dot(mid - p0, nrm) * nrm;  // inside each side, with tolerance
  const float w0 = glm::dot(glm::cross(p1 - p0, q - p0), nrm) / glm::length(p1 - p0);
  const float w1 = glm::dot(glm::cross(p2 - p1, q - p1), nrm) / glm::length(p2 - p1);
  const float w2 = glm::dot(glm::cross(p0 - p2, q - p2), nrm) / glm::length(p0 - p2);
  return w0 > -kTol && w1 > -kTol && w2 > -kTol;
}

bool SealingSurfaces::sideAlong(uint32_t t, const DiffractionEdge& e, HeldSpan& span) const {
  const auto& tr = mesh_.triangles[t];
  const glm::vec3 p[3] = {mesh_.vertices[tr[0]], mesh_.vertices[tr[1]], mesh_.vertices[tr[2]]};
  auto isCorner = [&](const glm::vec3& v) { return v == p[0] || v == p[1] || v == p[2]; };
  if (isCorner(e.a) && isCorner(e.b)) return false;  // one of the edge's own faces
  if (glm::length(glm::cross(p[1] - p[0], p[2] - p[0])) == 0.f) return false;  // degenerate
  auto offLine = [&](const glm::vec3& v) {
    const glm::vec3 r = v - e.a;
    return glm::length(r - glm::dot(r, e.direction) * e.direction);
  };
  for (int i = 0; i < 3; ++i) {
    glm::vec3 u = p[i], v = p[(i + 1) % 3];
    if (offLine(u) > kTol || offLine(v) > kTol) continue;
    float tu = glm::dot(u - e.a, e.direction), tv = glm::dot(v - e.a, e.direction);
    if (tu > tv) {
      std::swap(tu, tv);
      std::swap(u, v);
    }
    span.lo = std::max(tu, 0.f);
    span.hi = std::min(tv, e.length);
    span.loCorner = tu > 0.f ? u : e.a;
    span.hiCorner = tv < e.length ? v : e.b;
    span.triangle = t;
    glm::vec3 in = p[(i + 2) % 3] - u;  // toward the third corner, square to the line
    span.inward = unitOrZero(in - glm::dot(in, e.direction) * e.direction);
    // A sheet's rim met by a face in another plane is a fold (the two make a wedge there);
    // within kFoldFlat of the sheet's own plane, either way, the surface runs on (sealed).
    constexpr float kFoldFlat = 0.999f;
    span.fold = isFreeEdge(e) && std::abs(glm::dot(span.inward, e.face0)) < kFoldFlat;
    return span.hi - span.lo > kMinPart;
  }
  return false;
}

std::vector<SealingSurfaces::Piece> SealingSurfaces::pieces(const DiffractionEdge& e,
                                                            std::vector<HeldSpan> held) const {
  std::vector<std::pair<float, glm::vec3>> cuts{{0.f, e.a}, {e.length, e.b}};
  for (const HeldSpan& h : held) {
    cuts.push_back({h.lo, h.loCorner});
    cuts.push_back({h.hi, h.hiCorner});
  }
  std::sort(cuts.begin(), cuts.end(),
            [](const auto& x, const auto& y) { return x.first < y.first; });
  std::vector<Piece> out;
  for (size_t i = 0; i + 1 < cuts.size(); ++i) {
    const float lo = cuts[i].first, hi = cuts[i + 1].first, mid = 0.5f * (lo + hi);
    if (!(hi - lo > 0.f)) continue;
    int fold = -1;  // -1 open, -2 sealed, else the fold's span
    for (size_t k = 0; k < held.size() && fold != -2; ++k) {
      if (!(held[k].lo <= mid && mid <= held[k].hi)) continue;
      // A second fold in the same plane is the first's other copy (a two-sided face).
      const bool same = fold >= 0 && glm::dot(held[k].inward, held[size_t(fold)].inward) > 0.999f;
      fold = held[k].fold && (fold == -1 || same) ? (fold == -1 ? int(k) : fold) : -2;
    }
    if (!out.empty() && out.back().fold == fold) {
      out.back().b = cuts[i + 1].second;
      out.back().hi = hi;
    } else {
      out.push_back({cuts[i].second, cuts[i + 1].second, lo, hi, fold});
    }
  }
  return out;
}

DiffractionEdge SealingSurfaces::foldEdge(const DiffractionEdge& e, const HeldSpan& fold,
                                          const std::vector<uint32_t>& surfaces) const {
  DiffractionEdge w = e;
  double ang =
      std::atan2(double(glm::dot(fold.inward, e.normal0)), double(glm::dot(fold.inward, e.face0)));
  if (ang < 0.0) ang += 2.0 * std::numbers::pi;
  w.open = float(ang);
  if (fold.triangle < surfaces.size()) w.surfaces[1] = surfaces[fold.triangle];
  return w;
}

void SealingSurfaces::appendOpenParts(const DiffractionEdge& e, uint32_t ownTriangle,
                                      const std::vector<uint32_t>& surfaces,
                                      std::vector<DiffractionEdge>& out) const {
  const std::vector<uint32_t> near = trianglesAlong(e);
  std::vector<HeldSpan> held;
  for (uint32_t t : near) {
    HeldSpan span;
    if (sideAlong(t, e, span))
      held.push_back(span);
    else if (holdsMidpoint(t, e))
      return;  // sealed whole (not at a side: a rim on a floor)
  }
  if (held.empty()) {
    out.push_back(e);
    return;
  }
  for (const Piece& piece : pieces(e, held)) {
    if (piece.fold == -2 || piece.hi - piece.lo < kMinPart) continue;
    DiffractionEdge part = e;  // its ends at the corners that cut it, as a welded mesh has them
    if (piece.fold >= 0) {
      // Both faces' rims meet here; the one whose face comes first in the mesh lays the wedge.
      const HeldSpan& f = held[size_t(piece.fold)];
      if (!(ownTriangle < f.triangle)) continue;
      part = foldEdge(e, f, surfaces);
      if (std::abs(double(part.open) - std::numbers::pi) < kFlatEdge) continue;
    }
    part.a = piece.a;
    part.b = piece.b;
    part.length = glm::distance(part.a, part.b);
    out.push_back(part);
  }
}

}  // namespace dpc
