// The wave band of a scene's source at its listeners, with the scene as it stands at one time
// (objects, source and listeners at their poses then): the geometry and tracer built here,
// then wave/wave_band.h. The wave band is a monopole's: a source's directivity is not applied.
//
// Control thread; allocates; throws InputError as simulateWaveBand does.
#pragma once

#include <span>

#include "scene/scene.h"
#include "wave/wave_band.h"

namespace dpc::wave {

/// The wave band of source `source` at each of `listeners` (indices into scene.listeners), at
/// scene time t seconds.
WaveBand sceneWaveBand(const SceneDesc& scene, size_t source, std::span<const size_t> listeners,
                       double t, const WaveBandOptions& options);

}  // namespace dpc::wave
