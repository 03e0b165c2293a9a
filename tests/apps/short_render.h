// A short offline render of a scene with its dry signals, for tests that compare two scenes
// (the same room in two forms): bit-identical for a seed, so any difference is the scenes'.
#pragma once

#include "runtime/offline_renderer.h"
#include "scene/scene.h"
#include "testing/test_scenes.h"

namespace dpc::test {

/// Renders `seconds` of listener 0 with `rays` per frame and a 0.5 s IR (the scene's seed).
inline OfflineListenerResult shortRender(const SceneDesc& scene, int rays, double seconds) {
  PropagationSettings ps = scene.propagation;
  ps.raysPerFrame = rays;
  ps.irLength = 0.5f;
  OfflineOptions opt;
  opt.durationSeconds = seconds;
  const DrySignals dry = loadDrySignals(scene);
  return renderOffline(shared(scene), ps, shared(dry), opt).listeners.at(0);
}

}  // namespace dpc::test
