// dpc_scene_data (include/dpc/dpc.h) to the SceneDesc and dry signals a scene file with the
// same content would give, checked with the scene file's bounds (docs/scene-format.md).
#pragma once

#include <cstring>
#include <type_traits>

#include "dpc/dpc.h"
#include "runtime/render_pipeline.h"
#include "scene/scene.h"

namespace dpc::api {

/// Any thread; no allocation. A caller's C enum field (dpc_output_format, dpc_rendering,
/// dpc_estimator, dpc_tracing) read as its integer value, so that a value outside the
/// enumeration (a caller's garbage) is compared, never loaded as the enum type.
template <class E>
long rawEnum(const E& field) {
  std::underlying_type_t<E> raw;
  std::memcpy(&raw, &field, sizeof raw);
  return long(raw);
}

/// Any thread. The OutputFormat of a `field` holding DPC_OUTPUT_MONO, _STEREO or _BINAURAL in
/// *out; false (and *out unchanged) for any other value, DPC_OUTPUT_SCENE included.
bool toOutputFormat(const dpc_output_format& field, OutputFormat* out);

/// Any thread; no allocation. What dpc_scene_data_init fills, at the current layout: zero
/// mesh, materials and sources, the listener at the origin, every other field the scene
/// file's default.
dpc_scene_data defaultSceneData();

/// Control thread. The scene of `data` (of the current layout, api/layouts.h readVersioned);
/// throws InputError naming the field ("dpc_scene_data: FIELD: problem") for a value out of range.
/// Allocates.
SceneDesc sceneFromData(const dpc_scene_data& data);

/// Control thread. The sources' dry signals with their gains applied (empty for a source
/// without signal, or for every source if `hostInputsOnly`). Allocates.
DrySignals drySignalsFromData(const dpc_scene_data& data, bool hostInputsOnly);

}  // namespace dpc::api
