#include "engine/geometry.h"

#include <cmath>
#include <cstdio>
#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/mat3x3.hpp>
#include <limits>
#include <stdexcept>

namespace dpc {

EmbreeDevice::EmbreeDevice() {
  device_ = rtcNewDevice(nullptr);
  if (!device_)
    throw std::runtime_error("Embree: cannot create a device (error " +
                             std::to_string(int(rtcGetDeviceError(nullptr))) + ")");
  rtcSetDeviceErrorFunction(device_, &EmbreeDevice::onError, this);
}

EmbreeDevice::~EmbreeDevice() {
  if (device_) rtcReleaseDevice(device_);
}

void EmbreeDevice::onError(void* self, RTCError code, const char* str) {
  auto* d = static_cast<EmbreeDevice*>(self);
  if (d->firstError_ == RTC_ERROR_NONE) {
    d->firstError_ = code;
    d->firstMessage_ = str ? str : "unknown error";
  }
}

void EmbreeDevice::throwIfError(const char* step) {
  if (firstError_ != RTC_ERROR_NONE)
    throw std::runtime_error(std::string("Embree: ") + firstMessage_ + ", during " + step);
}

RTCGeometry Geometry::addTriangles(const Mesh& mesh, const std::vector<Material>& materials,
                                   float patchSize, bool bounds) {
  if (mesh.triangles.empty()) throw std::invalid_argument("Geometry: mesh has no triangles");
  if (mesh.materialIndex.size() != mesh.triangles.size())
    throw std::invalid_argument("Geometry: one material index per triangle required");
  const size_t nv = mesh.vertices.size(), nt = mesh.triangles.size();
  RTCGeometry geom = rtcNewGeometry(device_.get(), RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0,
                                                        RTC_FORMAT_FLOAT3, 3 * sizeof(float), nv));
  auto* idx = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(
      geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), nt));
  device_.throwIfError("creating the triangle buffers");
  for (size_t i = 0; i < nv; ++i) {
    v[3 * i + 0] = mesh.vertices[i].x;
    v[3 * i + 1] = mesh.vertices[i].y;
    v[3 * i + 2] = mesh.vertices[i].z;
    if (bounds) {
      boundsMin_ = glm::min(boundsMin_, mesh.vertices[i]);
      boundsMax_ = glm::max(boundsMax_, mesh.vertices[i]);
    }
  }
  const size_t first = patching_.size();
  patching_.resize(first + nt);
  materialOf_.resize(first + nt);
  for (size_t t = 0; t < nt; ++t) {
    const auto& tri = mesh.triangles[t];
    for (int k = 0; k < 3; ++k) {
      if (tri[k] >= nv) {
        rtcReleaseGeometry(geom);
        throw std::invalid_argument("Geometry: triangle index out of range");
      }
      idx[3 * t + k] = tri[k];
    }
    if (mesh.materialIndex[t] >= materials.size()) {
      rtcReleaseGeometry(geom);
      throw std::invalid_argument("Geometry: material index out of range");
    }
    materialOf_[first + t] = mesh.materialIndex[t];
    const glm::vec3 &a = mesh.vertices[tri[0]], &b = mesh.vertices[tri[1]],
                    &c = mesh.vertices[tri[2]];
    patching_[first + t] = TrianglePatching::build(a, b, c, patchSize);
    surfaceArea_ += 0.5 * glm::length(glm::cross(glm::dvec3(b - a), glm::dvec3(c - a)));
  }
  rtcCommitGeometry(geom);
  return geom;
}

Geometry::Geometry(const Mesh& mesh, const std::vector<Material>& materials, float patchSize,
                   const std::vector<ObjectDesc>& objects) {
  if (!(patchSize > 0.f)) throw std::invalid_argument("Geometry: patch size must be > 0");
  for (const Material& m : materials) {
    reflectance_.push_back(Bands(1.f) - m.absorption);
    scattering_.push_back(m.scattering);
    if (m.scattering.min() != m.scattering.max()) scatteringVariesWithBand_ = true;
  }
  boundsMin_ = glm::vec3(std::numeric_limits<float>::max());
  boundsMax_ = glm::vec3(-std::numeric_limits<float>::max());
  scene_ = rtcNewScene(device_.get());
  if (objects.empty()) {
    rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_HIGH);
    RTCGeometry geom = addTriangles(mesh, materials, patchSize, true);
    rtcAttachGeometry(scene_, geom);
    rtcReleaseGeometry(geom);
    rtcCommitScene(scene_);
    device_.throwIfError("building the BVH");
    return;
  }
  // Two levels: every mesh (the static one too) gets its own BVH, built once; the top-level
  // scene holds only instances, so moving an object rebuilds a BVH over a handful of boxes.
  rtcSetSceneFlags(scene_, RTC_SCENE_FLAG_DYNAMIC);
  rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_LOW);
  instances_.resize(1 + objects.size());
  for (size_t i = 0; i < instances_.size(); ++i) {
    Instance& in = instances_[i];
    in.firstTriangle = uint32_t(patching_.size());
    const Mesh& m = i == 0 ? mesh : objects[i - 1].mesh;
    in.scene = rtcNewScene(device_.get());
    rtcSetSceneBuildQuality(in.scene, RTC_BUILD_QUALITY_HIGH);
    RTCGeometry geom = addTriangles(m, materials, patchSize, i == 0);
    rtcAttachGeometry(in.scene, geom);
    rtcReleaseGeometry(geom);
    rtcCommitScene(in.scene);
    in.instance = rtcNewGeometry(device_.get(), RTC_GEOMETRY_TYPE_INSTANCE);
    rtcSetGeometryInstancedScene(in.instance, in.scene);
    rtcAttachGeometryByID(scene_, in.instance, unsigned(i));
    if (i > 0) objects_.push_back(&in);
  }
  device_.throwIfError("building the object BVHs");
  setObjectPose(~size_t(0), Pose{});  // the static mesh: identity
  for (size_t k = 0; k < objects.size(); ++k) {
    const auto& key = objects[k].trajectory;
    setObjectPose(k, key.empty() ? Pose{} : Pose{key.front().position, key.front().rotation});
  }
  commitPoses();
}

void Geometry::setObjectPose(size_t object, const Pose& pose) {
  Instance& in = object == ~size_t(0) ? instances_.front() : *objects_[object];
  in.rotation = pose.rotation;
  const glm::mat3 r = glm::mat3_cast(pose.rotation);
  // 3x4 column-major: the rotation's three columns, then the translation.
  const float xfm[12] = {r[0][0], r[0][1],         r[0][2],         r[1][0],
                         r[1][1], r[1][2],         r[2][0],         r[2][1],
                         r[2][2], pose.position.x, pose.position.y, pose.position.z};
  rtcSetGeometryTransform(in.instance, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, xfm);
  rtcCommitGeometry(in.instance);
}

void Geometry::commitPoses() {
  if (instances_.empty()) return;
  rtcCommitScene(scene_);
  device_.throwIfError("moving the objects");
}

void Geometry::resolveHit(unsigned instID, unsigned primID, const glm::vec3& ng,
                          SurfaceHit& hit) const {
  if (instID == RTC_INVALID_GEOMETRY_ID || instances_.empty()) {
    hit.triangle = primID;
    hit.normal = glm::normalize(ng);
    return;
  }
  // Instanced hits report the normal in the instance's local frame (RTCHit, Embree 3).
  const Instance& in = instances_[instID];
  hit.triangle = in.firstTriangle + primID;
  hit.normal = glm::normalize(in.rotation * ng);
}

Geometry::~Geometry() {
  if (scene_) rtcReleaseScene(scene_);
  for (Instance& in : instances_) {
    if (in.instance) rtcReleaseGeometry(in.instance);
    if (in.scene) rtcReleaseScene(in.scene);
  }
}

bool Geometry::intersect(const glm::vec3& org, const glm::vec3& dir, float tnear, float tfar,
                         SurfaceHit& hit) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh;
  rh.ray.org_x = org.x;
  rh.ray.org_y = org.y;
  rh.ray.org_z = org.z;
  rh.ray.dir_x = dir.x;
  rh.ray.dir_y = dir.y;
  rh.ray.dir_z = dir.z;
  rh.ray.tnear = tnear;
  rh.ray.tfar = tfar;
  rh.ray.time = 0.f;
  rh.ray.mask = 0xffffffffu;
  rh.ray.id = 0;
  rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(scene_, &context, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
  hit.t = rh.ray.tfar;
  hit.barycentric = {1.f - rh.hit.u - rh.hit.v, rh.hit.u, rh.hit.v};
  resolveHit(rh.hit.instID[0], rh.hit.primID, glm::vec3(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z),
             hit);
  return true;
}

void Geometry::intersect16(const RayPacket16& rays, float tnear, float tfar,
                           PacketHits16& hits) const {
  constexpr int K = RayPacket16::kSize;
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
  alignas(64) int valid[K];
  RTCRayHit16 rh;  // RTC_ALIGN(64) in rtcore_ray.h
  for (int i = 0; i < K; ++i) {
    valid[i] = rays.active[i] ? -1 : 0;
    rh.ray.org_x[i] = rays.org[i].x;
    rh.ray.org_y[i] = rays.org[i].y;
    rh.ray.org_z[i] = rays.org[i].z;
    rh.ray.dir_x[i] = rays.dir[i].x;
    rh.ray.dir_y[i] = rays.dir[i].y;
    rh.ray.dir_z[i] = rays.dir[i].z;
    rh.ray.tnear[i] = tnear;
    rh.ray.tfar[i] = tfar;
    rh.ray.time[i] = 0.f;
    rh.ray.mask[i] = 0xffffffffu;
    rh.ray.id[i] = unsigned(i);
    rh.ray.flags[i] = 0;
    rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
    rh.hit.primID[i] = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
  }
  rtcIntersect16(valid, scene_, &context, &rh);
  for (int i = 0; i < K; ++i) {
    hits.found[i] = rays.active[i] && rh.hit.geomID[i] != RTC_INVALID_GEOMETRY_ID;
    if (!hits.found[i]) continue;
    SurfaceHit& hit = hits.hit[i];
    hit.t = rh.ray.tfar[i];
    hit.barycentric = {1.f - rh.hit.u[i] - rh.hit.v[i], rh.hit.u[i], rh.hit.v[i]};
    resolveHit(rh.hit.instID[0][i], rh.hit.primID[i],
               glm::vec3(rh.hit.Ng_x[i], rh.hit.Ng_y[i], rh.hit.Ng_z[i]), hit);
  }
}

bool Geometry::occluded(const glm::vec3& org, const glm::vec3& dir, float tnear, float tfar) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay ray;
  ray.org_x = org.x;
  ray.org_y = org.y;
  ray.org_z = org.z;
  ray.dir_x = dir.x;
  ray.dir_y = dir.y;
  ray.dir_z = dir.z;
  ray.tnear = tnear;
  ray.tfar = tfar;
  ray.time = 0.f;
  ray.mask = 0xffffffffu;
  ray.id = 0;
  ray.flags = 0;
  rtcOccluded1(scene_, &context, &ray);
  return ray.tfar < 0.f;  // Embree sets tfar = -inf when occluded
}

}  // namespace dpc
