// The wave band's grid: the scene's air as nodes of a rectilinear grid, with each node's open
// faces and the admittance of the walls its other faces meet.
//
// Layout: the grid covers the mesh's bounding box with count[a] nodes along axis a, spacing
// spacing[a] = extent[a] / count[a] (each at most the target spacing, so a box-shaped room's
// walls lie exactly half a spacing outside its outermost nodes: the room keeps its size).
// Node (i, j, k) sits at boundsMin + ((i, j, k) + 1/2) * spacing. Arrays carry one node of
// padding on every side (never air), so a neighbour index never leaves them.
//
// A face between two neighbouring nodes is open when the segment between their centres meets
// no triangle; a closed face takes the admittance of the material of the first triangle the
// segment meets (from the lower node), and a face leaving the bounding box without meeting
// a triangle takes admittance 1 (absorbing at normal incidence: a mesh that is not closed
// radiates out of the box). Air is every node reached through open faces from the seed
// points (the sources and receivers), so a closed room's outside is never simulated.
//
// Construction: control thread; allocates (about 14 bytes per node of the bounding box while
// building, then the air mask and the boundary list), traces 3 segments per node with the
// Tracer (TBB workers); throws InputError naming `wave.max_frequency` when the grid would
// exceed kMaxWaveNodes. Reads: any thread, no allocation.
// Source: the finite-volume view of boundaries in S. Bilbao, "Modeling of complex geometries
// and boundary conditions in finite difference/finite volume time domain room acoustics
// simulation", IEEE TASLP 21(7), 2013.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <glm/vec3.hpp>
#include <span>
#include <string>
#include <vector>

#include "engine/geometry.h"
#include "engine/tracer.h"

namespace dpc::wave {

/// Most nodes a grid may have (bounding box, padding included): 4e8 nodes are about 5 GB of
/// solver state (12 bytes a node) and 4 GB more while the grid is built; beyond, the scene is
/// too large for the maximum frequency asked.
inline constexpr double kMaxWaveNodes = 4e8;

/// Where the grid lies: node counts per axis (without padding), spacing per axis (m) and the
/// low corner of the bounding box it covers (m).
struct GridLayout {
  std::array<int, 3> count{};
  glm::dvec3 spacing{0.0};
  glm::dvec3 boundsMin{0.0};

  /// Array dimensions with the padding: count + 2 per axis.
  std::array<size_t, 3> dims() const {
    return {size_t(count[0]) + 2, size_t(count[1]) + 2, size_t(count[2]) + 2};
  }
  size_t arraySize() const { const auto d = dims(); return d[0] * d[1] * d[2]; }
  /// Array index of node (i, j, k) in padded coordinates (1 .. count).
  size_t index(size_t i, size_t j, size_t k) const {
    const auto d = dims();
    return i + d[0] * (j + d[1] * k);
  }
  /// Centre of the node at padded coordinates (i, j, k), metres.
  glm::dvec3 centre(size_t i, size_t j, size_t k) const {
    return boundsMin + (glm::dvec3(double(i), double(j), double(k)) - 0.5) * spacing;
  }
};

/// The layout covering [lo, hi] with spacing at most `target` metres per axis (at least one
/// node per axis). Throws InputError(file, field) beyond kMaxWaveNodes, `field` the setting
/// that gave the target (WaveSettings::spacingField).
GridLayout layoutFor(const glm::dvec3& lo, const glm::dvec3& hi, double target,
                     const std::string& file, const std::string& field);

/// Wall codes of a closed face: kWallOutside for the bounding box's edge, else the material's
/// index + 1; 0 for an open face.
inline constexpr uint16_t kWallOutside = 0xFFFF;

/// A node of the air with a closed face: its open faces (bit 2a: the -a neighbour, bit 2a+1:
/// the +a neighbour), each face's wall code, and the sum over its closed faces of
/// beta / spacing[axis] (1/m), beta the wall's normalised admittance (rho c / Z).
struct BoundaryNode {
  uint32_t index = 0;
  uint8_t openFaces = 0;
  std::array<uint16_t, 6> walls{};
  float admittancePerMetre = 0.f;
};

struct WaveGrid {
  GridLayout layout;
  /// 1 for air, 0 elsewhere, per array index.
  std::vector<float> air;
  /// The air's nodes with at least one closed face, in array order.
  std::vector<BoundaryNode> boundary;
  size_t airNodes = 0;
};

/// Builds the grid of `layout` over the scene of `geometry` and `tracer` (its objects at the
/// poses the tracer holds), air flooded from `seeds` (metres; a seed outside the box or on no
/// air node is skipped). Walls have no admittance until setAdmittances.
WaveGrid buildWaveGrid(const GridLayout& layout, const Tracer& tracer, const Geometry& geometry,
                       std::span<const glm::vec3> seeds);

/// Sets every boundary node's admittance from per-material normalised admittance `beta`
/// (indexed as the geometry's materials; the box's edge has 1). No allocation.
void setAdmittances(WaveGrid& grid, std::span<const float> beta);

}  // namespace dpc::wave
