#include "engine/small_reflectors.h"

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>

#include "engine/diffraction_edges.h"

namespace dpc {

namespace {

/// Per triangle of `mesh`, whether its flat surface stands free (freeStandingExtents).
std::vector<bool> freeStandingTriangles(const Mesh& mesh) {
  const std::vector<uint32_t> surfaces = flatSurfaces(mesh);
  const std::vector<float> extent = freeStandingExtents(
      mesh, surfaces, surfaceBodies(mesh, surfaces), candidateEdges(mesh, surfaces));
  std::vector<bool> out(mesh.triangles.size());
  for (size_t t = 0; t < out.size(); ++t) out[t] = std::isfinite(extent[surfaces[t]]);
  return out;
}

double triangleArea(const Mesh& mesh, size_t t) {
  const auto& v = mesh.triangles[t];
  const glm::dvec3 a(mesh.vertices[v[0]]), b(mesh.vertices[v[1]]), c(mesh.vertices[v[2]]);
  return 0.5 * glm::length(glm::cross(b - a, c - a));
}

}  // namespace

SmallReflectors::SmallReflectors(const std::vector<const Mesh*>& meshes,
                                 const CoplanarFaces& faces) {
  std::vector<bool> free;
  std::vector<double> area;  // per triangle number of a face: the face's area
  for (const Mesh* m : meshes) {
    const std::vector<bool> f = freeStandingTriangles(*m);
    const size_t first = free.size();
    free.insert(free.end(), f.begin(), f.end());
    area.resize(free.size(), 0.0);
    for (size_t t = 0; t < m->triangles.size(); ++t)
      area[faces.faceOf(uint32_t(first + t))] += triangleArea(*m, t);
  }
  area_.assign(free.size(), 0.f);
  for (size_t t = 0; t < free.size(); ++t) {
    const uint32_t face = faces.faceOf(uint32_t(t));
    if (face == t && free[t]) area_[t] = float(area[t]);
  }
}

Bands SmallReflectors::factor(uint32_t face, double cosIncidence, double before, double after,
                              double speedOfSound) const {
  Bands out(1.f);
  const double a = double(area(face));
  if (!(a > 0.0) || !(before > 0.0) || !(after > 0.0)) return out;
  const double zone = before * after / (before + after);  // L, m
  for (int b = 0; b < kNumBands; ++b) {
    const double ratio =
        a * std::clamp(cosIncidence, 0.0, 1.0) * bandCentreExactHz(b) / (speedOfSound * zone);
    out[b] = float(std::min(1.0, ratio * ratio));
  }
  return out;
}

}  // namespace dpc
