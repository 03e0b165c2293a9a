#include "engine/geometry.h"

#include <glm/geometric.hpp>
#include <limits>
#include <stdexcept>

#include "scene/transmission.h"

namespace dpc {

void checkMeshTriangles(const Mesh& mesh) {
  if (mesh.triangles.empty()) throw std::invalid_argument("Geometry: mesh has no triangles");
  for (const auto& tri : mesh.triangles)
    for (auto v : tri)
      if (v >= mesh.vertices.size())
        throw std::invalid_argument("Geometry: triangle index out of range");
}

void Geometry::addTriangles(const Mesh& mesh, size_t materialCount, float patchSize, bool bounds) {
  checkMeshTriangles(mesh);
  if (mesh.materialIndex.size() != mesh.triangles.size())
    throw std::invalid_argument("Geometry: one material index per triangle required");
  if (bounds)
    for (const glm::vec3& v : mesh.vertices) {
      boundsMin_ = glm::min(boundsMin_, v);
      boundsMax_ = glm::max(boundsMax_, v);
    }
  const size_t first = patching_.size(), nt = mesh.triangles.size();
  patching_.resize(first + nt);
  materialOf_.resize(first + nt);
  for (size_t t = 0; t < nt; ++t) {
    if (mesh.materialIndex[t] >= materialCount)
      throw std::invalid_argument("Geometry: material index out of range");
    materialOf_[first + t] = mesh.materialIndex[t];
    const auto& tri = mesh.triangles[t];
    const glm::vec3 &a = mesh.vertices[tri[0]], &b = mesh.vertices[tri[1]],
                    &c = mesh.vertices[tri[2]];
    patching_[first + t] = TrianglePatching::build(a, b, c, patchSize);
    surfaceArea_ += 0.5 * glm::length(glm::cross(glm::dvec3(b - a), glm::dvec3(c - a)));
  }
}

Geometry::Geometry(const Mesh& mesh, const std::vector<Material>& materials, float patchSize,
                   const std::vector<ObjectDesc>& objects) {
  if (!(patchSize > 0.f)) throw std::invalid_argument("Geometry: patch size must be > 0");
  for (const Material& m : materials) {
    reflectance_.push_back(Bands(1.f) - m.absorption);
    scattering_.push_back(m.scattering);
    transmittance_.push_back(transmittanceOf(m.transmissionLossDb));
    transmits_.push_back(dpc::transmits(m.transmissionLossDb) ? 1 : 0);
    anyTransmission_ = anyTransmission_ || transmits_.back() != 0;
    if (m.scattering.min() != m.scattering.max()) scatteringVariesWithBand_ = true;
  }
  boundsMin_ = glm::vec3(std::numeric_limits<float>::max());
  boundsMax_ = glm::vec3(-std::numeric_limits<float>::max());
  addTriangles(mesh, materials.size(), patchSize, true);
  for (const ObjectDesc& object : objects)
    addTriangles(object.mesh, materials.size(), patchSize, false);
}

}  // namespace dpc
