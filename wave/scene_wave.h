// The wave band of a scene's source at its listeners, with the scene as it stands at one time
// (objects, source and listeners at their poses then): the geometry and tracer built here,
// then wave/wave_band.h. The wave band is a monopole's: a source's directivity is not applied.
//
// Control thread; allocates; throws InputError as simulateWaveBand does.
#pragma once

#include <functional>
#include <memory>
#include <span>
#include <string>

#include "scene/scene.h"
#include "wave/wave_band.h"
#include "wave/wave_join.h"

namespace dpc::wave {

/// The wave band of source `source` at each of `listeners` (indices into scene.listeners), at
/// scene time t seconds.
WaveBand sceneWaveBand(const SceneDesc& scene, size_t source, std::span<const size_t> listeners,
                       double t, const WaveBandOptions& options);

/// The same at any `receivers` (a bake's probes), with the scene's objects and source at time
/// t seconds.
WaveBand sceneWaveBandAt(const SceneDesc& scene, size_t source,
                         std::span<const WavePoint> receivers, double t,
                         const WaveBandOptions& options);

/// The first thing of `scene` that moves (its field, e.g. "sources[1].trajectory"), or "" when
/// nothing does: the wave band is simulated for one pose of the scene.
std::string firstMovingField(const SceneDesc& scene);

/// The wave bands of every source at `listeners` for a render of `scene` (wave.enabled), as a
/// set to join to its IRs (irSeconds long, the scene's rate and output format). Throws
/// InputError(scene file, "wave.enabled", ...) when something moves (the wave band holds one
/// pose), as simulateWaveBand for the rest. progress(source, steps done, steps) may be empty.
std::shared_ptr<const WaveBandSet> sceneWaveBands(
    const SceneDesc& scene, std::span<const size_t> listeners, double irSeconds,
    const std::function<void(size_t, size_t, size_t)>& progress);

}  // namespace dpc::wave
