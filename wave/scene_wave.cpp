#include "wave/scene_wave.h"

#include <string>
#include <vector>

#include "engine/embree_tracer.h"
#include "engine/geometry.h"
#include "scene/trajectory.h"

namespace dpc::wave {

WaveBand sceneWaveBand(const SceneDesc& scene, size_t source, std::span<const size_t> listeners,
                       double t, const WaveBandOptions& options) {
  const Geometry geometry(scene.mesh, scene.materials, scene.propagation.patchSize, scene.objects);
  EmbreeTracer tracer(scene.mesh, scene.objects);
  for (size_t k = 0; k < scene.objects.size(); ++k)
    tracer.setObjectPose(k, objectPoseAt(scene.objects[k], t));
  tracer.commitPoses();
  const WavePoint from{sourcePositionAt(scene.sources[source], t),
                       "sources[" + std::to_string(source) + "].position"};
  std::vector<WavePoint> at;
  for (size_t l : listeners)
    at.push_back({listenerPositionAt(scene.listeners[l], t),
                  "listeners[" + std::to_string(l) + "].position"});
  return simulateWaveBand(scene, tracer, geometry, from, at, options);
}

}  // namespace dpc::wave
