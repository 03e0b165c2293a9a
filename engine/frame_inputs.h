// FrameInputs: everything one propagation frame of a Simulation depends on that may change from
// frame to frame, as one plain value passed down (Simulation::runFrame): where the listeners
// and sources are and how they are turned, where the moving objects are, which pairs start
// over or are played from a bake, and how many rays each emitter traces. What is fixed for a
// run (the scene's geometry and materials, the PropagationSettings) is given at construction
// instead. docs/design.md, "Data flow", shows it flowing down to the tracer, one TraceRequest
// (engine/propagation.h) per emitter.
//
// Units: metres; rotations unit quaternions in glTF order (x, y, z, w) mapping local to world;
// orientations as scene/scene.h's Orientation. A plain value: copy, keep and reuse it freely
// (a caller that refills one object every frame allocates only while its vectors grow).
#pragma once

#include <cstdint>
#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>
#include <vector>

#include "scene/scene.h"

namespace dpc {

/// A receiver sphere (a listener's; from the listeners, a source's of the listener's radius).
struct ListenerSphere {
  glm::vec3 position{0.f};  ///< metres
  float radius = 0.5f;      ///< metres, > 0
};

struct FrameInputs {
  /// The listeners traced this frame, at least one; index l is the listener index of the
  /// results and of the path identifiers.
  std::vector<ListenerSphere> listeners;
  /// Per listener, its orientation (the frame its directional responses are read in); empty
  /// or shorter than listeners: the default orientation (yaw 0, pitch 0, roll 0).
  std::vector<Orientation> listenerOrientations;
  /// One position per scene source.
  std::vector<glm::vec3> sourcePositions;
  /// One rotation per scene source (each directional source's forward axis is rotation * +x);
  /// empty: every source as the scene turns it at time 0.
  std::vector<glm::quat> sourceRotations;
  /// One pose per scene object; empty: every object where the scene puts it at time 0.
  std::vector<Pose> objectPoses;
  /// Per source and per listener, non-zero when it jumped since the previous frame (a
  /// teleport): its pairs' caches start over before this frame. Empty or shorter: none.
  std::vector<uint8_t> sourceRestarts, listenerRestarts;
  /// skippedPairs[l * sources + s] != 0: pair (s, l) is played from a bake and not traced
  /// this frame (Simulation, "Skipped pairs"). Empty or shorter: nothing skipped.
  std::vector<uint8_t> skippedPairs;
  /// Rays each emitter (a source, or from the listeners a listener) traces this frame, >= 1;
  /// 0: PropagationSettings::raysPerFrame. Every estimator normalises a frame by the rays it
  /// traced, so frames of different counts average without bias.
  int raysPerEmitter = 0;
  /// Calibration: segments leaving the sources also count as listener hits, to compare with
  /// the analytic direct sound 1/(4 pi r^2) (TraceRequest::includeDirectRays). Renders leave
  /// it off: the direct sound is analytic.
  bool includeDirectRays = false;

  /// Whether source s is restarted, listener l restarted, pair (s, l) skipped (sources: the
  /// scene's source count).
  bool sourceRestarted(size_t s) const { return s < sourceRestarts.size() && sourceRestarts[s]; }
  bool listenerRestarted(size_t l) const {
    return l < listenerRestarts.size() && listenerRestarts[l];
  }
  bool skipped(size_t s, size_t l, size_t sources) const {
    const size_t pair = l * sources + s;
    return pair < skippedPairs.size() && skippedPairs[pair] != 0;
  }
};

}  // namespace dpc
