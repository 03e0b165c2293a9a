// The files an offline render writes, one set per listener.
#pragma once

#include <string>
#include <vector>

#include "apps/demo/flags.h"
#include "scene/scene.h"

namespace dpc::demo {

/// The files one offline render writes for one listener (empty = not asked for).
struct OutputPaths {
  std::string audio, ir, energy;
};

/// OUT.wav -> OUT-NAME.wav (the listener's name before the extension); "" stays "".
/// Any thread. Allocates.
std::string withListener(const std::string& path, const std::string& name);

/// Offline without --listener renders every listener: one listener writes the names as given,
/// several write OUT-NAME.wav (and IR-NAME.wav, ER-NAME.csv) each, in the scene's listener
/// order. Any thread. Allocates; no errors.
std::vector<OutputPaths> offlineOutputs(const SceneDesc& scene, const Flags& fl);

}  // namespace dpc::demo
