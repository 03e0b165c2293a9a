// Loading a bake for playback (engine/baked_field.h): reads a dpc-bake file and validates it
// against the scene it is to be played in. Refused, with one line naming the file and the
// attribute or dataset (InputError): anything BakeFile::open refuses for reading (a missing,
// truncated, damaged or corrupt file, another format or version, a dataset of the wrong shape,
// a probe failing its checksum, a file marked complete with a probe missing), a bake whose
// source count differs from the scene's (`sources/position`), a bake of another scene or of
// other settings: the playback groups of the settings hash differ (bake/settings_hash.h: the
// attribute of the first that differs, `ir_length_s` for another response length), an
// incomplete bake (`complete`), and a bake whose arrays would not fit the memory a render may
// plan for (`energy`; engine/workload.h).
// Control thread; allocates (the whole bake: BakedField::bytes()).
#pragma once

#include <memory>
#include <string>

#include "engine/baked_field.h"
#include "scene/scene.h"

namespace dpc::bake {

std::shared_ptr<const BakedField> loadBakedField(const std::string& path, const SceneDesc& scene);
/// The same for a run whose propagation settings are `settings` instead of the scene's (a
/// command line's overrides, e.g. dpc-demo --max-order).
std::shared_ptr<const BakedField> loadBakedField(const std::string& path, const SceneDesc& scene,
                                                 const PropagationSettings& settings);

}  // namespace dpc::bake
