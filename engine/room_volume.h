// The volume of a scene's room, for the reflection-density law of the IR synthesis
// (synthesis/dirac_sequence.h).
#pragma once

#include "scene/scene.h"

namespace dpc {

/// Volume for the reflection-density law, m^3: the enclosed volume of a closed mesh by the
/// divergence theorem, V = |sum_triangles v0 . (v1 x v2)| / 6 (exact for any closed,
/// consistently oriented triangle mesh; edges matched by vertex position, weldedVertexIds);
/// for a mesh with boundary edges (an open scene) or a volume below 1 % of the bounding box,
/// the bounding-box volume. At least 1 m^3. Any thread; allocates a temporary edge table; no
/// errors.
double roomVolume(const Mesh& mesh);

}  // namespace dpc
