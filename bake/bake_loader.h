// Loading a bake for playback (engine/baked_field.h): reads a dpc-bake file and validates it
// against the scene it is to be played in. Refused, with one line naming the file and the
// attribute or dataset (InputError): anything BakeFile::open refuses (a missing, truncated or
// corrupt file, another format or version, a dataset of the wrong shape), a bake of another
// scene (`mesh_hash` differs from sceneHash(scene)), an incomplete bake (`complete`), and a bake
// whose source count differs from the scene's (`sources/position`), and a bake whose arrays
// would not fit the memory a render may plan for (`energy`; engine/workload.h).
// Control thread; allocates (the whole bake: BakedField::bytes()).
#pragma once

#include <memory>
#include <string>

#include "engine/baked_field.h"
#include "scene/scene.h"

namespace dpc::bake {

std::shared_ptr<const BakedField> loadBakedField(const std::string& path, const SceneDesc& scene);

}  // namespace dpc::bake
