// EmbreeTracer: the Tracer (engine/tracer.h) over an Embree 3 BVH of the scene's triangles.
//
// The Embree device and scenes are owned here and released here only (RAII), following the
// Embree tutorials: the device error callback is registered once at creation and records the
// first error, which build steps turn into a std::runtime_error. Without moving objects the
// mesh is one BVH (one level); with objects every mesh, the static one too, gets its own BVH,
// built once, and the top-level scene holds only Embree instances, so moving an object
// rebuilds a BVH over a handful of boxes. Single queries map to rtcIntersect1 / rtcOccluded1,
// batches to rtcIntersect16 / rtcOccluded16 per packet of Tracer::kPacketSize rays.
//
// Construction: control/propagation thread; allocates; throws std::invalid_argument on a mesh
// without triangles or with a vertex index out of range (checkMeshTriangles) and
// std::runtime_error on an Embree error. Queries and poses: as Tracer says.
#pragma once

#include <memory>
#include <vector>

#include "engine/tracer.h"
#include "scene/scene.h"

namespace dpc {

class EmbreeTracer final : public Tracer {
 public:
  /// mesh: the static triangles (metres); objects: moving rigid objects in scene order, each
  /// placed at its first keyframe's pose (identity without keyframes).
  explicit EmbreeTracer(const Mesh& mesh, const std::vector<ObjectDesc>& objects = {});
  ~EmbreeTracer() override;
  EmbreeTracer(const EmbreeTracer&) = delete;
  EmbreeTracer& operator=(const EmbreeTracer&) = delete;

  bool intersect(const TraceRay& ray, SurfaceHit& hit) const override;
  bool intersect(const TraceRay& ray, const TriangleFilter& filter, SurfaceHit& hit) const override;
  bool occluded(const TraceRay& ray) const override;
  void intersect(std::span<const TraceRay> rays, std::span<TraceHit> hits) const override;
  void occluded(std::span<const TraceRay> rays, std::span<bool> blocked) const override;

  size_t objectCount() const override;
  void setObjectPose(size_t object, const Pose& pose) override;
  void commitPoses() override;

 private:
  struct State;  ///< Embree handles (embree_tracer.cpp): no Embree type in this header
  std::unique_ptr<State> state_;
};

}  // namespace dpc
