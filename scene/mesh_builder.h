// The one mesh builder: a RawMesh (scene/obj_reader.h, or arrays from the C API) becomes the
// engine's Mesh under one cleaning rule, the same for files and for data built in code.
//
// Control thread; allocates; throws InputError naming the mesh's file (or API structure).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "scene/obj_reader.h"
#include "scene/scene.h"

namespace dpc {

/// Per triangle of `raw`, the index into `materials` of its usemtl name; a face before any
/// usemtl takes the material named "default". Throws InputError(raw.file, "usemtl NAME") for a
/// name `materials` does not define (sceneFile names where it should be defined), or
/// (raw.file, "face N") for a face without usemtl when there is no "default".
std::vector<uint32_t> materialIndicesByName(const RawMesh& raw,
                                            const std::vector<Material>& materials,
                                            const std::string& sceneFile);

/// Builds the mesh from raw.positions and raw.triangles with materialIndex (one per triangle).
/// Cleaning rule: a triangle of zero area, or a sliver whose height is below 1e-6 of its
/// longest edge, is dropped, and so is one on the same three positions with the same winding
/// as an earlier triangle (a coincident copy adds no surface, only tracing work; the opposite
/// winding, a zero-thickness wall's other side, is kept); each kind's count and first dropped
/// face go into one line of `warnings`. Throws InputError(raw.file, "", ...) when every triangle is
/// dropped.
Mesh buildMesh(const RawMesh& raw, const std::vector<uint32_t>& materialIndex,
               std::vector<std::string>& warnings);

}  // namespace dpc
