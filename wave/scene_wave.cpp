#include "wave/scene_wave.h"

#include <string>
#include <vector>

#include "common/input_error.h"
#include "engine/embree_tracer.h"
#include "engine/geometry.h"
#include "scene/trajectory.h"

namespace dpc::wave {

WaveBand sceneWaveBand(const SceneDesc& scene, size_t source, std::span<const size_t> listeners,
                       double t, const WaveBandOptions& options) {
  std::vector<WavePoint> at;
  for (size_t l : listeners)
    at.push_back({listenerPositionAt(scene.listeners[l], t),
                  "listeners[" + std::to_string(l) + "].position"});
  return sceneWaveBandAt(scene, source, at, t, options);
}

WaveBand sceneWaveBandAt(const SceneDesc& scene, size_t source,
                         std::span<const WavePoint> receivers, double t,
                         const WaveBandOptions& options) {
  const Geometry geometry(scene.mesh, scene.materials, scene.propagation.patchSize, scene.objects);
  EmbreeTracer tracer(scene.mesh, scene.objects);
  for (size_t k = 0; k < scene.objects.size(); ++k)
    tracer.setObjectPose(k, objectPoseAt(scene.objects[k], t));
  tracer.commitPoses();
  const WavePoint from{sourcePositionAt(scene.sources[source], t),
                       "sources[" + std::to_string(source) + "].position"};
  return simulateWaveBand(scene, tracer, geometry, from, receivers, options);
}

namespace {

/// True when keyframes put the thing at more than one place or rotation.
template <class Keys>
bool keysMove(const Keys& keys) {
  for (size_t k = 1; k < keys.size(); ++k)
    if (keys[k].position != keys[0].position) return true;
  return false;
}

bool objectTurns(const ObjectDesc& o) {
  for (const ObjectKeyframe& k : o.trajectory)
    if (k.rotation != o.trajectory.front().rotation) return true;
  return false;
}

}  // namespace

std::string firstMovingField(const SceneDesc& scene) {
  for (size_t s = 0; s < scene.sources.size(); ++s)
    if (keysMove(scene.sources[s].trajectory))
      return "sources[" + std::to_string(s) + "].trajectory";
  for (size_t l = 0; l < scene.listeners.size(); ++l)
    if (keysMove(scene.listeners[l].trajectory))
      return "listeners[" + std::to_string(l) + "].trajectory";
  for (size_t o = 0; o < scene.objects.size(); ++o)
    if (keysMove(scene.objects[o].trajectory) || objectTurns(scene.objects[o]))
      return "objects[" + std::to_string(o) + "].trajectory";
  return "";
}

std::shared_ptr<const WaveBandSet> sceneWaveBands(
    const SceneDesc& scene, std::span<const size_t> listeners, double irSeconds,
    const std::function<void(size_t, size_t, size_t)>& progress) {
  if (const std::string moving = firstMovingField(scene); !moving.empty())
    throw InputError(scene.path, "wave.enabled",
                     "the wave band is simulated for one pose of the scene, and " + moving +
                         " moves (render it without the wave band, hold it still, or play it "
                         "from a bake that carries the wave band: dpc-bake)");
  auto set = std::make_shared<WaveBandSet>(
      scene.listeners.size(), scene.sources.size(), scene.audio.output,
      double(scene.wave.crossover()), double(scene.wave.maxFrequencyHz), scene.audio.sampleRate);
  for (size_t s = 0; s < scene.sources.size(); ++s) {
    WaveBandOptions opt;
    opt.seconds = irSeconds;
    opt.sampleRate = scene.audio.sampleRate;
    if (progress) opt.progress = [&, s](size_t done, size_t total) { progress(s, done, total); };
    const WaveBand band = sceneWaveBand(scene, s, listeners, 0.0, opt);
    for (size_t k = 0; k < listeners.size(); ++k) set->set(listeners[k], s, band.irs[k]);
  }
  return set;
}

}  // namespace dpc::wave
