// How the C API's structures spell a scene file's field paths, for validate()'s messages
// (scene/validate.h Origin::spell).
#pragma once

#include <string>
#include <vector>

#include "scene/scene.h"
#include "scene/validate.h"

namespace dpc::api {

/// "propagation.cache_tau" -> "cache_tau", "listeners[0].radius" -> "listener_radius",
/// "listeners[2].yaw" -> "additional_listeners[1].yaw_degrees", "materials.NAME.absorption[3]"
/// -> "materials[i].absorption[3]", "materials.NAME.transmission_loss_db[3]" ->
/// "material_transmissions[i].loss_db[3]", "mesh.triangles[4][2]" -> "mesh.indices[14]"; other paths
/// unchanged. Control thread; allocates.
std::string apiFieldName(const std::string& path, const std::vector<Material>& materials);

/// An Origin named `name` ("dpc_scene_data", "dpc_engine_options") that spells fields the C
/// API's way; it refers to `scene`'s materials, so `scene` must outlive it.
Origin apiOrigin(const char* name, const SceneDesc& scene);

}  // namespace dpc::api
