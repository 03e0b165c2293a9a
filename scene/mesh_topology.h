// Mesh topology: which vertices of a triangle mesh are one point, so that shared edges and
// closedness can be found when an exporter writes a corner once per face.
//
// Threads: any thread. Allocation: O(vertices). Errors: none.
#pragma once

#include <cstdint>
#include <vector>

#include "scene/scene.h"

namespace dpc {

/// Per vertex of mesh.vertices, the index of the first vertex at exactly the same position (bit
/// for bit, -0 and +0 alike): the mesh's topology (shared edges, closedness) when an exporter
/// writes a corner once per face.
std::vector<uint32_t> weldedVertexIds(const Mesh& mesh);

}  // namespace dpc
