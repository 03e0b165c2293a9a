// dpc-demo --bake BAKE.h5: the bake static sources are played from (runtime/baked_playback.h).
#pragma once

#include <memory>

#include "apps/demo/flags.h"
#include "engine/baked_field.h"
#include "runtime/baked_playback.h"
#include "scene/scene.h"

namespace dpc::demo {

/// Loads and checks fl.bake for `scene` run with `settings` (the scene's propagation settings
/// with the command line's overrides; bake/bake_loader.h); nullptr when --bake is not given.
/// Throws InputError naming the file and field for a bake that does not fit the scene, and
/// naming --bake when dpc-demo was built without HDF5. Main thread; allocates.
std::shared_ptr<const BakedField> loadBakeFlag(const Flags& fl, const SceneDesc& scene,
                                               const PropagationSettings& settings);

/// One line on stdout: the bake's probes and memory, and how many responses it gave, how many
/// stayed live (moving sources) and how many listener positions saw no probe (live fallback).
void printBakeSummary(const BakedField& bake, const BakedPlayback::Stats& stats);

}  // namespace dpc::demo
