#include "engine/sphere_grid.h"

#include <algorithm>
#include <cmath>
#include <glm/common.hpp>
#include <limits>

namespace dpc {

void SphereGrid::fitCells(const glm::vec3& extent, size_t spheres) {
  // Cells of about equal sides whose count is kCellsPerSphere per sphere.
  const double volume = double(extent.x) * extent.y * extent.z;
  const double target = std::max(1.0, kCellsPerSphere * double(spheres));
  const double side = std::cbrt(volume / target);
  for (int a = 0; a < 3; ++a) {
    const double n = side > 0.0 ? std::round(double(extent[a]) / side) : 1.0;
    cells_[size_t(a)] = int(std::clamp(n, 1.0, double(kMaxCellsPerAxis)));
    side_[a] = extent[a] / float(cells_[size_t(a)]);
    inverseSide_[a] = side_[a] > 0.f ? 1.f / side_[a] : 0.f;
  }
}

int SphereGrid::cellOf(float x, int axis) const {
  const float v = std::floor((x - lo_[axis]) * inverseSide_[axis]);
  return int(std::clamp(v, 0.f, float(cells_[size_t(axis)] - 1)));
}

void SphereGrid::build(std::span<const glm::vec4> spheres) {
  boxes_.resize(spheres.size());
  offsets_.clear();
  members_.clear();
  if (spheres.empty()) return;
  lo_ = glm::vec3(std::numeric_limits<float>::infinity());
  hi_ = -lo_;
  for (const glm::vec4& s : spheres) {
    lo_ = glm::min(lo_, glm::vec3(s) - s.w);
    hi_ = glm::max(hi_, glm::vec3(s) + s.w);
  }
  fitCells(hi_ - lo_, spheres.size());
  const glm::vec3 margin = kMargin * side_;
  for (size_t i = 0; i < spheres.size(); ++i) {
    const glm::vec3 c(spheres[i]);
    for (int a = 0; a < 3; ++a) {
      boxes_[i].lo[size_t(a)] = cellOf(c[a] - spheres[i].w - margin[a], a);
      boxes_[i].hi[size_t(a)] = cellOf(c[a] + spheres[i].w + margin[a], a);
    }
  }
  // Counting sort of (cell, sphere) pairs into offsets_ / members_.
  const size_t cells = size_t(cells_[0]) * size_t(cells_[1]) * size_t(cells_[2]);
  counts_.assign(cells + 1, 0);
  auto forEachCell = [&](const CellBox& b, auto&& g) {
    for (int z = b.lo[2]; z <= b.hi[2]; ++z)
      for (int y = b.lo[1]; y <= b.hi[1]; ++y)
        for (int x = b.lo[0]; x <= b.hi[0]; ++x) g(cellIndex({x, y, z}));
  };
  for (const CellBox& b : boxes_) forEachCell(b, [&](uint32_t c) { ++counts_[c + 1]; });
  for (size_t c = 0; c < cells; ++c) counts_[c + 1] += counts_[c];
  offsets_.assign(counts_.begin(), counts_.end());
  members_.resize(offsets_.back());
  for (uint32_t i = 0; i < boxes_.size(); ++i)
    forEachCell(boxes_[i], [&](uint32_t c) { members_[counts_[c]++] = i; });
}

bool SphereGrid::start(const glm::vec3& org, const glm::vec3& dir, float segEnd, Walk& w) const {
  if (boxes_.empty()) return false;
  // The segment clipped to the grid's box (slab test; a zero direction component with the
  // origin outside that slab leaves nothing).
  float t0 = 0.f, t1 = segEnd;
  for (int a = 0; a < 3; ++a) {
    if (dir[a] == 0.f) {
      if (org[a] < lo_[a] || org[a] > hi_[a]) return false;
      continue;
    }
    const float inv = 1.f / dir[a];
    const float ta = (lo_[a] - org[a]) * inv, tb = (hi_[a] - org[a]) * inv;
    t0 = std::max(t0, std::min(ta, tb));
    t1 = std::min(t1, std::max(ta, tb));
  }
  if (!(t0 <= t1)) return false;
  w.tEnd = t1;
  const glm::vec3 entry = org + t0 * dir;
  for (int a = 0; a < 3; ++a) {
    const size_t i = size_t(a);
    w.cell[i] = cellOf(entry[a], a);
    w.step[i] = dir[a] > 0.f ? 1 : dir[a] < 0.f ? -1 : 0;
    if (w.step[i] == 0) {
      w.tMax[a] = w.tDelta[a] = std::numeric_limits<float>::infinity();
      continue;
    }
    const float boundary = lo_[a] + float(w.cell[i] + (w.step[i] > 0 ? 1 : 0)) * side_[a];
    w.tMax[a] = (boundary - org[a]) / dir[a];
    w.tDelta[a] = side_[a] / std::abs(dir[a]);
  }
  w.first = true;
  return true;
}

bool SphereGrid::advance(Walk& w) const {
  const int a =
      w.tMax.x <= w.tMax.y ? (w.tMax.x <= w.tMax.z ? 0 : 2) : (w.tMax.y <= w.tMax.z ? 1 : 2);
  if (!(w.tMax[a] <= w.tEnd)) return false;
  const size_t i = size_t(a);
  w.previous = w.cell;
  w.first = false;
  w.cell[i] += w.step[i];
  if (w.cell[i] < 0 || w.cell[i] >= cells_[i]) return false;
  w.tMax[a] += w.tDelta[a];
  return true;
}

}  // namespace dpc
