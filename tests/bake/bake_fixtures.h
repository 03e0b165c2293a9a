// The scene and settings the bake tests share: a 10 x 3 x 7 m shoebox and a quick bake
// (500 rays x 4 frames per probe, 0.5 s responses, one thread). The scene's ir_length is the
// bake's, as baked playback requires (bake/settings_hash.h).
#pragma once

#include "bake/bake_layout.h"
#include "bake/probe_bake.h"
#include "bake/probe_grid.h"
#include "bake/settings_hash.h"
#include "testing/test_scenes.h"

namespace dpc::bake::test_fixtures {

inline BakeSettings quickSettings();

inline SceneDesc shoebox() {
  SceneDesc s = test::makeShoebox({10.f, 3.f, 7.f}, Bands(0.2f), 0.5f, {2.f, 1.6f, 3.5f},
                                  {8.f, 1.6f, 3.5f});
  s.propagation.irLength = float(quickSettings().irLength);
  return s;
}

inline BakeSettings quickSettings() {
  BakeSettings s;
  s.rays = 500;
  s.frames = 4;
  s.irLength = 0.5;
  s.threads = 1;
  return s;
}

/// The header of a bake of `scene` with `settings` on a grid of `spacing` metres (one source).
inline BakeHeader headerFor(const SceneDesc& scene, const BakeSettings& settings,
                            double spacing) {
  BakeHeader h;
  h.scenePath = "/tmp/scene.json";
  h.settings = settings;
  h.grid.spacingM = spacing;
  h.grid.radiusM = scene.listeners[0].radius;
  h.probes = makeProbeGrid(scene, h.grid, "scene.json");
  h.hashes = settingsHash(scene, settings, h.probes.positions);
  h.seed = scene.propagation.seed;
  h.sources = {scene.sources[0].position};
  h.shape = probeShape(scene, settings);
  return h;
}

}  // namespace dpc::bake::test_fixtures
