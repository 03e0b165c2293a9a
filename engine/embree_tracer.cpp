#include "engine/embree_tracer.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <array>
#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/mat3x3.hpp>
#include <stdexcept>
#include <string>

#include "engine/geometry.h"

namespace dpc {

namespace {

constexpr int kLanes = int(Tracer::kPacketSize);
static_assert(kLanes == 16, "batches map onto rtcIntersect16 / rtcOccluded16");

/// Owns an RTCDevice and records its first error. Not copyable.
class EmbreeDevice {
 public:
  EmbreeDevice() {
    device_ = rtcNewDevice(nullptr);
    if (!device_)
      throw std::runtime_error("Embree: cannot create a device (error " +
                               std::to_string(int(rtcGetDeviceError(nullptr))) + ")");
    rtcSetDeviceErrorFunction(device_, &EmbreeDevice::onError, this);
  }
  ~EmbreeDevice() {
    if (device_) rtcReleaseDevice(device_);
  }
  EmbreeDevice(const EmbreeDevice&) = delete;
  EmbreeDevice& operator=(const EmbreeDevice&) = delete;
  RTCDevice get() const { return device_; }
  /// Throws std::runtime_error("Embree: <what>, during <step>") if an error was recorded.
  void throwIfError(const char* step) const {
    if (firstError_ != RTC_ERROR_NONE)
      throw std::runtime_error(std::string("Embree: ") + firstMessage_ + ", during " + step);
  }

 private:
  static void onError(void* self, RTCError code, const char* str) {
    auto* d = static_cast<EmbreeDevice*>(self);
    if (d->firstError_ == RTC_ERROR_NONE) {
      d->firstError_ = code;
      d->firstMessage_ = str ? str : "unknown error";
    }
  }
  RTCDevice device_ = nullptr;
  RTCError firstError_ = RTC_ERROR_NONE;
  std::string firstMessage_;
};

/// Fills a packet's rays (Embree's SoA layout) and valid flags from kLanes rays, one per lane.
template <class Ray16>
void fillPacket(const TraceRay* rays, Ray16& r, int* valid) {
  for (int i = 0; i < kLanes; ++i) {
    const TraceRay& ray = rays[i];
    valid[i] = ray.active ? -1 : 0;
    r.org_x[i] = ray.org.x;
    r.org_y[i] = ray.org.y;
    r.org_z[i] = ray.org.z;
    r.dir_x[i] = ray.dir.x;
    r.dir_y[i] = ray.dir.y;
    r.dir_z[i] = ray.dir.z;
    r.tnear[i] = ray.tnear;
    r.tfar[i] = ray.tfar;
    r.time[i] = 0.f;
    r.mask[i] = 0xffffffffu;
    r.id[i] = unsigned(i);
    r.flags[i] = 0;
  }
}

/// The rays of the packet starting at `first`: the batch's own memory for a full packet, else
/// a copy in `tail` with idle lanes after the batch's last ray.
const TraceRay* packetRays(std::span<const TraceRay> rays, size_t first,
                           std::array<TraceRay, kLanes>& tail) {
  if (rays.size() - first >= size_t(kLanes)) return rays.data() + first;
  tail.fill(TraceRay{.active = false});
  std::copy(rays.begin() + std::ptrdiff_t(first), rays.end(), tail.begin());
  return tail.data();
}

RTCRay singleRay(const TraceRay& in) {
  RTCRay ray;
  ray.org_x = in.org.x;
  ray.org_y = in.org.y;
  ray.org_z = in.org.z;
  ray.dir_x = in.dir.x;
  ray.dir_y = in.dir.y;
  ray.dir_z = in.dir.z;
  ray.tnear = in.tnear;
  ray.tfar = in.tfar;
  ray.time = 0.f;
  ray.mask = 0xffffffffu;
  ray.id = 0;
  ray.flags = 0;
  return ray;
}

}  // namespace

/// Embree handles: the device, the top-level scene and, with objects, one instanced BVH per
/// mesh ([0] the static mesh at identity, [1 + k] object k).
struct EmbreeTracer::State {
  /// One instanced mesh: its BVH, its instance in the top-level scene, its first triangle's
  /// global number and its current rotation (hit normals come back in local coordinates).
  struct Instance {
    RTCScene scene = nullptr;
    RTCGeometry instance = nullptr;
    uint32_t firstTriangle = 0;
    glm::quat rotation{1.f, 0.f, 0.f, 0.f};
  };

  EmbreeDevice device;
  RTCScene scene = nullptr;
  std::vector<Instance> instances;

  ~State() {
    if (scene) rtcReleaseScene(scene);
    for (Instance& in : instances) {
      if (in.instance) rtcReleaseGeometry(in.instance);
      if (in.scene) rtcReleaseScene(in.scene);
    }
  }
  /// A committed Embree triangle geometry of mesh (checked by checkMeshTriangles).
  RTCGeometry triangles(const Mesh& mesh);
  void buildSingleLevel(const Mesh& mesh);
  void buildInstances(const Mesh& mesh, const std::vector<ObjectDesc>& objects);
  void setPose(Instance& in, const Pose& pose);
  /// Global triangle number of an Embree hit.
  uint32_t triangleOf(unsigned instID, unsigned primID) const {
    if (instID == RTC_INVALID_GEOMETRY_ID || instances.empty()) return primID;
    return instances[instID].firstTriangle + primID;
  }
  /// Global triangle number and world normal from an Embree hit.
  void resolveHit(unsigned instID, unsigned primID, const glm::vec3& ng, SurfaceHit& hit) const;
  /// The closest hit of one ray under `context`; false on a miss.
  bool closest(const TraceRay& ray, RTCIntersectContext& context, SurfaceHit& hit) const;

  /// A query's context with a TriangleFilter: Embree hands the context's address to the
  /// filter callback, which reads the rest from behind it.
  struct FilteredContext {
    RTCIntersectContext context;  ///< first: its address is the whole struct's
    const State* state = nullptr;
    TriangleFilter filter;
  };
  /// Embree's context filter: rejects the hits whose triangle the query's filter refuses.
  static void rejectRefused(const RTCFilterFunctionNArguments* args);
};

/// Every scene, the instanced ones too, runs a query's context filter when it has one (each
/// query without one pays a test of a null pointer per hit).
constexpr RTCSceneFlags kFilterable = RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION;

RTCGeometry EmbreeTracer::State::triangles(const Mesh& mesh) {
  checkMeshTriangles(mesh);
  const size_t nv = mesh.vertices.size(), nt = mesh.triangles.size();
  RTCGeometry geom = rtcNewGeometry(device.get(), RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0,
                                                        RTC_FORMAT_FLOAT3, 3 * sizeof(float), nv));
  auto* idx = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(
      geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), nt));
  device.throwIfError("creating the triangle buffers");
  for (size_t i = 0; i < nv; ++i) {
    v[3 * i + 0] = mesh.vertices[i].x;
    v[3 * i + 1] = mesh.vertices[i].y;
    v[3 * i + 2] = mesh.vertices[i].z;
  }
  for (size_t t = 0; t < nt; ++t)
    for (size_t k = 0; k < 3; ++k) idx[3 * t + k] = mesh.triangles[t][k];
  rtcCommitGeometry(geom);
  return geom;
}

void EmbreeTracer::State::buildSingleLevel(const Mesh& mesh) {
  rtcSetSceneFlags(scene, kFilterable);
  rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
  RTCGeometry geom = triangles(mesh);
  rtcAttachGeometry(scene, geom);
  rtcReleaseGeometry(geom);
  rtcCommitScene(scene);
  device.throwIfError("building the BVH");
}

void EmbreeTracer::State::buildInstances(const Mesh& mesh, const std::vector<ObjectDesc>& objects) {
  rtcSetSceneFlags(scene, RTCSceneFlags(RTC_SCENE_FLAG_DYNAMIC | kFilterable));
  rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_LOW);
  instances.resize(1 + objects.size());
  uint32_t first = 0;
  for (size_t i = 0; i < instances.size(); ++i) {
    Instance& in = instances[i];
    const Mesh& m = i == 0 ? mesh : objects[i - 1].mesh;
    in.firstTriangle = first;
    first += uint32_t(m.triangles.size());
    in.scene = rtcNewScene(device.get());
    rtcSetSceneFlags(in.scene, kFilterable);
    rtcSetSceneBuildQuality(in.scene, RTC_BUILD_QUALITY_HIGH);
    RTCGeometry geom = triangles(m);
    rtcAttachGeometry(in.scene, geom);
    rtcReleaseGeometry(geom);
    rtcCommitScene(in.scene);
    in.instance = rtcNewGeometry(device.get(), RTC_GEOMETRY_TYPE_INSTANCE);
    rtcSetGeometryInstancedScene(in.instance, in.scene);
    rtcAttachGeometryByID(scene, in.instance, unsigned(i));
  }
  device.throwIfError("building the object BVHs");
}

void EmbreeTracer::State::setPose(Instance& in, const Pose& pose) {
  in.rotation = pose.rotation;
  const glm::mat3 r = glm::mat3_cast(pose.rotation);
  // 3x4 column-major: the rotation's three columns, then the translation.
  const float xfm[12] = {r[0][0], r[0][1],         r[0][2],         r[1][0],
                         r[1][1], r[1][2],         r[2][0],         r[2][1],
                         r[2][2], pose.position.x, pose.position.y, pose.position.z};
  rtcSetGeometryTransform(in.instance, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, xfm);
  rtcCommitGeometry(in.instance);
}

void EmbreeTracer::State::resolveHit(unsigned instID, unsigned primID, const glm::vec3& ng,
                                     SurfaceHit& hit) const {
  hit.triangle = triangleOf(instID, primID);
  if (instID == RTC_INVALID_GEOMETRY_ID || instances.empty()) {
    hit.normal = glm::normalize(ng);
    return;
  }
  // Instanced hits report the normal in the instance's local frame (RTCHit, Embree 3).
  hit.normal = glm::normalize(instances[instID].rotation * ng);
}

EmbreeTracer::EmbreeTracer(const Mesh& mesh, const std::vector<ObjectDesc>& objects)
    : state_(std::make_unique<State>()) {
  state_->scene = rtcNewScene(state_->device.get());
  if (objects.empty()) {
    state_->buildSingleLevel(mesh);
    return;
  }
  state_->buildInstances(mesh, objects);
  state_->setPose(state_->instances.front(), Pose{});  // the static mesh: identity
  for (size_t k = 0; k < objects.size(); ++k) {
    const auto& key = objects[k].trajectory;
    setObjectPose(k, key.empty() ? Pose{} : Pose{key.front().position, key.front().rotation});
  }
  commitPoses();
}

EmbreeTracer::~EmbreeTracer() = default;

size_t EmbreeTracer::objectCount() const {
  return state_->instances.empty() ? 0 : state_->instances.size() - 1;
}

void EmbreeTracer::setObjectPose(size_t object, const Pose& pose) {
  state_->setPose(state_->instances[1 + object], pose);
}

void EmbreeTracer::commitPoses() {
  if (state_->instances.empty()) return;
  rtcCommitScene(state_->scene);
  state_->device.throwIfError("moving the objects");
}

bool EmbreeTracer::State::closest(const TraceRay& ray, RTCIntersectContext& context,
                                  SurfaceHit& hit) const {
  RTCRayHit rh;
  rh.ray = singleRay(ray);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(scene, &context, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
  hit.t = rh.ray.tfar;
  hit.barycentric = {1.f - rh.hit.u - rh.hit.v, rh.hit.u, rh.hit.v};
  resolveHit(rh.hit.instID[0], rh.hit.primID, glm::vec3(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z),
             hit);
  return true;
}

void EmbreeTracer::State::rejectRefused(const RTCFilterFunctionNArguments* args) {
  const auto* c = reinterpret_cast<const FilteredContext*>(args->context);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] == 0) continue;
    const uint32_t t = c->state->triangleOf(RTCHitN_instID(args->hit, args->N, i, 0),
                                            RTCHitN_primID(args->hit, args->N, i));
    if (!c->filter.accepts(c->filter.self, t)) args->valid[i] = 0;
  }
}

bool EmbreeTracer::intersect(const TraceRay& ray, SurfaceHit& hit) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  return state_->closest(ray, context, hit);
}

bool EmbreeTracer::intersect(const TraceRay& ray, const TriangleFilter& filter,
                             SurfaceHit& hit) const {
  State::FilteredContext c;
  rtcInitIntersectContext(&c.context);
  if (filter.accepts) c.context.filter = &State::rejectRefused;
  c.state = state_.get();
  c.filter = filter;
  return state_->closest(ray, c.context, hit);
}

bool EmbreeTracer::occluded(const TraceRay& ray) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay r = singleRay(ray);
  rtcOccluded1(state_->scene, &context, &r);
  return r.tfar < 0.f;  // Embree sets tfar = -inf when occluded
}

void EmbreeTracer::intersect(std::span<const TraceRay> rays, std::span<TraceHit> hits) const {
  const State& st = *state_;
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
  std::array<TraceRay, kLanes> tail;
  for (size_t first = 0; first < rays.size(); first += kLanes) {
    const TraceRay* lanes = packetRays(rays, first, tail);
    alignas(64) int valid[kLanes];
    RTCRayHit16 rh;  // RTC_ALIGN(64) in rtcore_ray.h
    fillPacket(lanes, rh.ray, valid);
    for (int i = 0; i < kLanes; ++i) {
      rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
      rh.hit.primID[i] = RTC_INVALID_GEOMETRY_ID;
      rh.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
    }
    rtcIntersect16(valid, st.scene, &context, &rh);
    const size_t n = std::min(size_t(kLanes), rays.size() - first);
    for (size_t i = 0; i < n; ++i) {
      TraceHit& out = hits[first + i];
      out.found = valid[i] && rh.hit.geomID[i] != RTC_INVALID_GEOMETRY_ID;
      if (!out.found) continue;
      out.surface.t = rh.ray.tfar[i];
      out.surface.barycentric = {1.f - rh.hit.u[i] - rh.hit.v[i], rh.hit.u[i], rh.hit.v[i]};
      st.resolveHit(rh.hit.instID[0][i], rh.hit.primID[i],
                    glm::vec3(rh.hit.Ng_x[i], rh.hit.Ng_y[i], rh.hit.Ng_z[i]), out.surface);
    }
  }
}

void EmbreeTracer::occluded(std::span<const TraceRay> rays, std::span<bool> blocked) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
  std::array<TraceRay, kLanes> tail;
  for (size_t first = 0; first < rays.size(); first += kLanes) {
    alignas(64) int valid[kLanes];
    RTCRay16 r;  // RTC_ALIGN(64) in rtcore_ray.h
    fillPacket(packetRays(rays, first, tail), r, valid);
    rtcOccluded16(valid, state_->scene, &context, &r);
    const size_t n = std::min(size_t(kLanes), rays.size() - first);
    for (size_t i = 0; i < n; ++i)
      blocked[first + i] = valid[i] && r.tfar[i] < 0.f;  // tfar = -inf when occluded
  }
}

}  // namespace dpc
