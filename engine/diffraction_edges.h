// The mesh's candidate diffracting edges, found once at load time for EdgeDiffraction
// (engine/diffraction.h): every edge shared by two non-coplanar triangles, and every edge used
// by one triangle only (the rim of an open surface), unless it lies on another surface (a
// partition's rim along the floor is sealed), and only the parts of it that no surface runs
// on past (a mesh with T-junctions: engine/sealed_edges.h). Edges are welded by position (an
// exporter may write a corner once per face), a double-sided face's second copy (the same three
// corners) adds no edges, and edges are sorted by their endpoints, so the order is deterministic.
//
// Internal to the engine. Any thread; allocates; no errors (degenerate triangles are skipped).
#pragma once

#include <vector>

#include "engine/diffraction.h"
#include "scene/scene.h"

namespace dpc {

/// Per triangle of `mesh`, the number of its flat surface: triangles that share an edge
/// (welded) across which they lie flat within the angle at which an edge stops diffracting
/// (kFlatEdge; either side, so the two copies of a double-sided sheet are one) are one
/// surface, numbered 0, 1, ... in the order of their first triangles. A door leaf is a surface
/// of its own, even when its hinge is welded to its frame; a wall's coplanar panels are one.
std::vector<uint32_t> flatSurfaces(const Mesh& mesh);

/// The bodies of the mesh's flat surfaces (SurfaceBodies, engine/diffraction.h), `surfaces`
/// numbered as flatSurfaces(mesh) gives them: body, closed, members and box filled (extent and
/// edges are freeStandingExtents's and surfaceEdges's).
SurfaceBodies surfaceBodies(const Mesh& mesh, const std::vector<uint32_t>& surfaces);

/// m: a closed body less than this across is a solid object (a box leaf, a pillar, a cabinet),
/// whose convex edges diffract; a larger one is taken for a room, whose corners do not.
inline constexpr float kSolidExtent = 5.f;

/// The share of its boundary's length that must be diffracting edges for a flat surface to
/// stand free (freeStandingExtents).
inline constexpr double kFreeStanding = 0.75;

/// Per flat surface (`surfaces`, flatSurfaces(mesh)), the length of its boundary (m): the sides
/// of its triangles used by no other of its triangles (welded corners; a double-sided copy adds
/// none).
std::vector<double> surfaceBoundaries(const Mesh& mesh, const std::vector<uint32_t>& surfaces);

/// Per flat surface (`surfaces`, flatSurfaces(mesh)), its extent, the diagonal of its
/// triangles' bounding box (m), when it stands free: at least kFreeStanding of its boundary's
/// length is edges (`edges`, candidateEdges) that bound it as a free-standing surface's rim
/// does (a sheet's free rim, an open body's edge, a solid's edge: `bodies`, surfaceBodies), as
/// a door leaf's, a panel's or a box's face's; +infinity for a
/// piece of a larger surface (a lintel panel between a wall's jambs meshed with T-junctions
/// meets them along sealed edges) or one that meets others in flat or concave folds (a room's
/// wall). Welded corners (scene/mesh_topology.h); a double-sided copy adds no boundary.
std::vector<float> freeStandingExtents(const Mesh& mesh, const std::vector<uint32_t>& surfaces,
                                       const SurfaceBodies& bodies,
                                       const std::vector<DiffractionEdge>& edges);

/// The bounding box (m) of the flat surfaces listed (SurfaceBodies::box); every point when one
/// lies outside `bodies` (a moving object's), none when the list is empty.
std::pair<glm::vec3, glm::vec3> boxOfSurfaces(const std::vector<uint32_t>& surfaces,
                                              const SurfaceBodies& bodies);

/// True when flat surface s belongs to a body too large to be taken away whole (kSolidExtent
/// across or more: a wall); false for a moving object's or an unknown surface.
bool largeBody(const SurfaceBodies& bodies, uint32_t s);

/// True when flat surface s belongs to a known static body that is not largeBody (a slat, a
/// post, a box leaf): one taken away whole; false for a large body's, a moving object's or an
/// unknown surface.
bool smallBody(const SurfaceBodies& bodies, uint32_t s);

/// Per flat surface, the indices into `edges` of the edges on its faces.
std::vector<std::vector<uint32_t>> surfaceEdges(size_t surfaceCount,
                                                const std::vector<DiffractionEdge>& edges);

/// The candidate edges of `mesh`, in the order of their endpoints; each edge's faces' surfaces
/// taken from `surfaces` (flatSurfaces(mesh)).
std::vector<DiffractionEdge> candidateEdges(const Mesh& mesh, const std::vector<uint32_t>& surfaces);

}  // namespace dpc
