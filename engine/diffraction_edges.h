// The mesh's candidate diffracting edges, found once at load time for EdgeDiffraction
// (engine/diffraction.h): every edge shared by two non-coplanar triangles, and every edge used
// by one triangle only (the rim of an open surface), unless it lies on another surface (a
// partition's rim along the floor is sealed). Edges are welded by position (an exporter may
// write a corner once per face), a double-sided face's second copy (the same three corners)
// adds no edges, and edges are sorted by their endpoints, so the order is deterministic.
//
// Internal to the engine. Any thread; allocates; no errors (degenerate triangles are skipped).
#pragma once

#include <vector>

#include "engine/diffraction.h"
#include "scene/scene.h"

namespace dpc {

/// The candidate edges of `mesh`, in the order of their endpoints; each edge's surface taken
/// from `surfaces` (per triangle, connectedSurfaces(mesh)).
std::vector<DiffractionEdge> candidateEdges(const Mesh& mesh, const std::vector<uint32_t>& surfaces);

}  // namespace dpc
