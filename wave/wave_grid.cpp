#include "wave/wave_grid.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>

#include "common/input_error.h"

namespace dpc::wave {
namespace {

/// Face codes: open, a triangle's material (index + 1), or the bounding box's edge.
constexpr uint16_t kOpen = 0;
constexpr uint16_t kOutside = kWallOutside;

/// The code of the face from the node at padded (i, j, k) to its +axis neighbour.
uint16_t traceFace(const GridLayout& g, const Tracer& tracer, const Geometry& geometry,
                   const std::array<size_t, 3>& at, int axis) {
  const glm::dvec3 from = g.centre(at[0], at[1], at[2]);
  glm::vec3 dir(0.f);
  dir[axis] = 1.f;
  // The segment to the neighbour, shifted forward by a ten-thousandth of a spacing: a surface
  // through a node centre (a wall on a grid plane) lies at t = 0 of one face and t = spacing
  // of the one below, where a ray's ends lose it to rounding; shifted, it closes the face
  // below it, and only that one.
  const float shift = 1e-4f * float(g.spacing[axis]);
  TraceRay ray{glm::vec3(from), dir, shift, float(g.spacing[axis]) + shift};
  SurfaceHit hit;
  if (tracer.intersect(ray, hit)) return uint16_t(geometry.materialOf(hit.triangle) + 1);
  const size_t c = at[size_t(axis)];
  const bool leavesBox = c == 0 || c == size_t(g.count[size_t(axis)]);
  return leavesBox ? kOutside : kOpen;
}

/// Codes of the three +faces of every node with padded coordinates in [0, count] per axis
/// (the faces from the low padding into the box included); 3 per array index.
std::vector<uint16_t> traceFaces(const GridLayout& g, const Tracer& tracer,
                                 const Geometry& geometry) {
  std::vector<uint16_t> codes(3 * g.arraySize(), kOutside);
  tbb::parallel_for(size_t(0), size_t(g.count[2]) + 1, [&](size_t k) {
    for (size_t j = 0; j <= size_t(g.count[1]); ++j)
      for (size_t i = 0; i <= size_t(g.count[0]); ++i) {
        const std::array<size_t, 3> at{i, j, k};
        const size_t index = g.index(i, j, k);
        for (int axis = 0; axis < 3; ++axis) {
          // A face between two padding nodes, or along the padding, is never used.
          bool inBox = true;
          for (int b = 0; b < 3; ++b)
            if (b != axis && at[size_t(b)] == 0) inBox = false;
          if (inBox) codes[3 * index + size_t(axis)] = traceFace(g, tracer, geometry, at, axis);
        }
      }
  });
  return codes;
}

/// Array strides per axis.
std::array<size_t, 3> strides(const GridLayout& g) {
  const auto d = g.dims();
  return {1, d[0], d[0] * d[1]};
}

/// The code of face `face` (2 axis + side) of the node at `index`.
uint16_t faceCode(const std::vector<uint16_t>& codes, const std::array<size_t, 3>& stride,
                  size_t index, int face) {
  const int axis = face / 2;
  const size_t owner = face % 2 ? index : index - stride[size_t(axis)];
  return codes[3 * owner + size_t(axis)];
}

/// Padded index of the node whose cell holds p, or nothing outside the box.
std::optional<size_t> nodeAt(const GridLayout& g, const glm::vec3& p) {
  std::array<size_t, 3> at{};
  for (int a = 0; a < 3; ++a) {
    const double c = std::floor((double(p[a]) - g.boundsMin[a]) / g.spacing[a]);
    if (!(c >= 0.0 && c < double(g.count[size_t(a)]))) return std::nullopt;
    at[size_t(a)] = size_t(c) + 1;
  }
  return g.index(at[0], at[1], at[2]);
}

/// Marks the nodes reached from the seeds through open faces.
std::vector<uint8_t> flood(const GridLayout& g, const std::vector<uint16_t>& codes,
                           std::span<const glm::vec3> seeds) {
  std::vector<uint8_t> reached(g.arraySize(), 0);
  std::vector<size_t> queue;
  for (const glm::vec3& s : seeds)
    if (const auto n = nodeAt(g, s); n && !reached[*n]) reached[*n] = 1, queue.push_back(*n);
  const auto stride = strides(g);
  while (!queue.empty()) {
    const size_t n = queue.back();
    queue.pop_back();
    for (int face = 0; face < 6; ++face) {
      if (faceCode(codes, stride, n, face) != kOpen) continue;
      const size_t m = face % 2 ? n + stride[size_t(face / 2)] : n - stride[size_t(face / 2)];
      if (!reached[m]) reached[m] = 1, queue.push_back(m);
    }
  }
  return reached;
}

}  // namespace

GridLayout layoutFor(const glm::dvec3& lo, const glm::dvec3& hi, double target,
                     const std::string& file, const std::string& field) {
  GridLayout g;
  g.boundsMin = lo;
  double nodes = 1.0;
  for (int a = 0; a < 3; ++a) {
    const double extent = std::max(hi[a] - lo[a], target);
    const double n = std::ceil(extent / target * (1.0 - 1e-9));
    nodes *= n + 2.0;
    g.count[size_t(a)] = int(std::min(n, 1e9));
    g.spacing[a] = extent / double(g.count[size_t(a)]);
  }
  if (!(nodes <= kMaxWaveNodes)) {
    char size[96];
    std::snprintf(size, sizeof size, "a grid of %.3g m would have %.3g nodes (at most %.3g)",
                  target, nodes, double(kMaxWaveNodes));
    const bool spacing = field == "wave.grid_spacing";
    throw InputError(file, field,
                     std::string(size) + (spacing ? ": raise the grid spacing" : ": lower the maximum frequency") +
                         " or simulate a smaller scene");
  }
  return g;
}

WaveGrid buildWaveGrid(const GridLayout& layout, const Tracer& tracer, const Geometry& geometry,
                       std::span<const glm::vec3> seeds) {
  const std::vector<uint16_t> codes = traceFaces(layout, tracer, geometry);
  const std::vector<uint8_t> reached = flood(layout, codes, seeds);
  const auto stride = strides(layout);
  WaveGrid grid;
  grid.layout = layout;
  grid.air.assign(layout.arraySize(), 0.f);
  for (size_t n = 0; n < reached.size(); ++n) {
    if (!reached[n]) continue;
    grid.air[n] = 1.f;
    ++grid.airNodes;
    BoundaryNode b{uint32_t(n), 0, {}, 0.f};
    for (int face = 0; face < 6; ++face) {
      b.walls[size_t(face)] = faceCode(codes, stride, n, face);
      if (b.walls[size_t(face)] == kOpen) b.openFaces = uint8_t(b.openFaces | (1u << face));
    }
    if (b.openFaces != 0x3F) grid.boundary.push_back(b);
  }
  return grid;
}

void setAdmittances(WaveGrid& grid, std::span<const float> beta) {
  for (BoundaryNode& b : grid.boundary) {
    double sum = 0.0;
    for (int face = 0; face < 6; ++face) {
      const uint16_t code = b.walls[size_t(face)];
      if (code == kOpen) continue;
      const double wall = code == kOutside ? 1.0 : double(beta[code - 1u]);
      sum += wall / grid.layout.spacing[face / 2];
    }
    b.admittancePerMetre = float(sum);
  }
}

}  // namespace dpc::wave
