// dpc studio's documents: the scene (sent once), a frame's state, the selected pair's energy
// response, and that response as dpc-demo --er-out's CSV (so dpc-analyze reads what the page
// shows). Control or server thread; allocates. Field names: docs/studio.md "API".
#pragma once

#include <string>

#include "apps/studio/studio_board.h"
#include "scene/scene.h"

namespace dpc::studio {

/// The static mesh (vertices, triangles, material per triangle), the materials with their
/// absorption per band, the sources' and listeners' names and the band centres.
std::string sceneJson(const SceneDesc& scene);

/// Poses, the direct sound, the exact early paths and the figures of a frame (no response).
std::string stateJson(const StudioFrame& frame);

/// The selected pair's energy response per band: {"frame", "binSeconds", "bands": [[...] x 8]}.
std::string responseJson(const StudioFrame& frame);

/// The selected pair's response as an energy-response CSV (analysis/energy_response_csv.h) with
/// the direct sound already in its bin (no "direct" row): dpc-analyze reads the same numbers.
std::string energyCsv(const StudioFrame& frame);

}  // namespace dpc::studio
