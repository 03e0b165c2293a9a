// --ir-out FILE.sofa: one listener's last-frame IRs as an AES69 GeneralFIR file
// (audio/sofa_writer.h), with the scene's poses converted to SOFA's frame.
#pragma once

#include <string>

#include "common/output_file.h"
#include "runtime/offline_renderer.h"
#include "scene/scene.h"

namespace dpc::demo {

/// Whether `path` names a SOFA file (extension ".sofa", any case).
bool isSofaPath(const std::string& path);

/// The listener's last IRs (one measurement per source, one receiver per output channel),
/// source and listener positions, view and up, converted from the scene's frame (y up,
/// forward +x at yaw 0, left -z) to SOFA's (z up): (x, y, z)_SOFA = (x, -z, y)_scene.
/// Receivers: the ears at +-0.09 m on the listener's y axis for binaural, the listener's
/// centre otherwise. Main thread; allocates; throws InputError naming `path`.
TempOutputFile stageIrSofa(const SceneDesc& scene, const OfflineListenerResult& r,
                           const std::string& path);

}  // namespace dpc::demo
