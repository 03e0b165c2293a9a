// Acoustic geometry: the per-triangle tables that propagation reads at a hit (patch
// subdivision, material reflectance and scattering) and the mesh's bounds and area. Ray
// queries are the Tracer's (engine/tracer.h); nothing here knows a ray-tracing library.
//
// Construction: control/propagation thread; allocates; throws std::invalid_argument on
// inconsistent input (the scene loader validates user input first). Accessors: any number of
// threads at once; no allocation; no errors.
#pragma once

#include <cstdint>
#include <glm/vec3.hpp>
#include <vector>

#include "common/bands.h"
#include "engine/patch.h"
#include "scene/scene.h"

namespace dpc {

/// Throws std::invalid_argument("Geometry: ...") if mesh has no triangles or a vertex index
/// out of range. Any thread; no allocation.
void checkMeshTriangles(const Mesh& mesh);

/// Triangle numbering: the static mesh's triangles come first (0 .. n-1), then each moving
/// object's in scene order. A triangle's number and its patches (defined on the object's own
/// mesh, in local coordinates) do not change when the object moves, so path identifiers and the
/// cache's grouping survive motion (docs/dynamic.md). A Tracer built from the same mesh and
/// objects numbers its hits the same way.
class Geometry {
 public:
  /// mesh: triangles and per-triangle material indices into materials; patchSize: lambda in
  /// metres (> 0). objects: moving rigid objects, whose triangles follow the mesh's; their
  /// patches are laid out on their own meshes in local coordinates.
  Geometry(const Mesh& mesh, const std::vector<Material>& materials, float patchSize,
           const std::vector<ObjectDesc>& objects = {});

  uint32_t triangleCount() const { return uint32_t(patching_.size()); }
  const TrianglePatching& patching(uint32_t tri) const { return patching_[tri]; }
  /// Energy reflection factor (1 - absorption) per band of triangle tri's material.
  const Bands& reflectance(uint32_t tri) const { return reflectance_[materialOf_[tri]]; }
  /// Scattering coefficient per octave band of triangle tri's material (ISO 17497-1).
  const Bands& scattering(uint32_t tri) const { return scattering_[materialOf_[tri]]; }
  /// Energy transmission coefficient tau = 10^(-R/10) per band of triangle tri's material
  /// (scene/transmission.h); zero for an opaque material.
  const Bands& transmittance(uint32_t tri) const { return transmittance_[materialOf_[tri]]; }
  /// True if triangle tri's material transmits in some band.
  bool transmits(uint32_t tri) const { return transmits_[materialOf_[tri]] != 0; }
  /// True if some material transmits: without, propagation and the direct sound take the
  /// opaque paths only (the same float operations as an engine without transmission).
  bool anyTransmission() const { return anyTransmission_; }
  /// True if some material's scattering coefficient differs between octave bands; the
  /// propagator then gives each ray one band (Propagator, docs/design.md).
  bool scatteringVariesWithBand() const { return scatteringVariesWithBand_; }
  uint32_t materialOf(uint32_t tri) const { return materialOf_[tri]; }

  /// Axis-aligned bounds of the mesh, metres.
  glm::vec3 boundsMin() const { return boundsMin_; }
  glm::vec3 boundsMax() const { return boundsMax_; }
  /// Total surface area, m^2.
  double surfaceArea() const { return surfaceArea_; }
  /// Bytes of per-triangle data held here (patching, material index), not counting the tracer.
  size_t bytesPerTriangle() const { return sizeof(TrianglePatching) + sizeof(uint32_t); }

 private:
  /// Appends mesh's triangles to the per-triangle tables; bounds: grow the bounding box.
  void addTriangles(const Mesh& mesh, size_t materialCount, float patchSize, bool bounds);

  std::vector<TrianglePatching> patching_;
  std::vector<uint32_t> materialOf_;
  std::vector<Bands> reflectance_;
  std::vector<Bands> scattering_;
  std::vector<Bands> transmittance_;
  std::vector<uint8_t> transmits_;
  bool scatteringVariesWithBand_ = false;
  bool anyTransmission_ = false;
  glm::vec3 boundsMin_{0.f}, boundsMax_{0.f};
  double surfaceArea_ = 0.0;
};

}  // namespace dpc
