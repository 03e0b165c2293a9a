#include "engine/reflection_scattering.h"

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>
#include <limits>

namespace dpc {
namespace {

/// A triangle's area and its second moment of area about `centre`, over its area (m^2): a
/// uniform triangle p0 + x e1 + y e2 has Var x = Var y = 1/18 and Cov(x, y) = -1/36.
struct AreaMoment {
  double area = 0.0;
  glm::dmat3 sum{0.0};  ///< area times the second moment about the origin
};

void addTriangle(const glm::dvec3& p0, const glm::dvec3& p1, const glm::dvec3& p2, AreaMoment& m,
                 glm::dvec3& areaCentroid) {
  const glm::dvec3 e1 = p1 - p0, e2 = p2 - p0;
  const double a = 0.5 * glm::length(glm::cross(e1, e2));
  const glm::dvec3 g = (p0 + p1 + p2) / 3.0;
  const glm::dmat3 cov = (glm::outerProduct(e1, e1) + glm::outerProduct(e2, e2)) / 18.0 -
                         (glm::outerProduct(e1, e2) + glm::outerProduct(e2, e1)) / 36.0;
  m.area += a;
  m.sum += a * (cov + glm::outerProduct(g, g));
  areaCentroid += a * g;
}

/// The triangles' vertices in their mesh's frame, Geometry's numbering, and each one's object
/// (-1 for the static mesh).
struct Corners {
  std::vector<std::array<glm::vec3, 3>> triangles;
  std::vector<int32_t> object;
};

Corners cornersOf(const Mesh& mesh, const std::vector<ObjectDesc>& objects) {
  Corners out;
  auto add = [&](const Mesh& m, int32_t object) {
    for (const auto& t : m.triangles) {
      out.triangles.push_back({m.vertices[t[0]], m.vertices[t[1]], m.vertices[t[2]]});
      out.object.push_back(object);
    }
  };
  add(mesh, -1);
  for (size_t k = 0; k < objects.size(); ++k) add(objects[k].mesh, int32_t(k));
  return out;
}

/// The least distance (m) along the unit `dir` from `org`, below `limit`, at which the ray
/// passes closest to the centre of a receiver sphere it enters; `limit` when none.
float nearestReceiver(std::span<const ListenerSphere> receivers, const glm::vec3& org,
                      const glm::vec3& dir, float limit) {
  for (const ListenerSphere& r : receivers) {
    const glm::vec3 oc = r.position - org;
    const float b = glm::dot(oc, dir);
    if (b > 0.f && b < limit && glm::dot(oc, oc) - b * b <= r.radius * r.radius) limit = b;
  }
  return limit;
}

}  // namespace

ReflectionScattering::ReflectionScattering(const Mesh& mesh, const std::vector<uint32_t>& surfaces,
                                           const std::vector<DiffractionEdge>& edges,
                                           const std::vector<ObjectDesc>& objects)
    : reflectors_(mesh, surfaces, edges, objects), rotation_(objects.size(), glm::mat3(1.f)) {
  const Corners corners = cornersOf(mesh, objects);
  moments_.resize(reflectors_.surfaceCount());
  for (uint32_t s = 0; s < moments_.size(); ++s) {
    AreaMoment m;
    glm::dvec3 centroid{0.0};
    for (uint32_t t : reflectors_.trianglesOf(s)) {
      if (t >= corners.triangles.size()) continue;
      const auto& c = corners.triangles[t];
      addTriangle(c[0], c[1], c[2], m, centroid);
      moments_[s].object = corners.object[t];
    }
    if (!(m.area > 0.0)) continue;
    centroid /= m.area;
    moments_[s].c = glm::mat3(m.sum / m.area - glm::outerProduct(centroid, centroid));
  }
  for (size_t k = 0; k < objects.size(); ++k) {
    const auto& key = objects[k].trajectory;
    if (!key.empty()) setObjectPose(k, Pose{key.front().position, key.front().rotation});
  }
}

void ReflectionScattering::setObjectPose(size_t object, const Pose& pose) {
  if (object < rotation_.size()) rotation_[object] = glm::mat3_cast(pose.rotation);
}

bool ReflectionScattering::standsFree(uint32_t t, const glm::vec3& litNormal,
                                      const glm::vec3& windingNormal) const {
  return reflectors_.standsFree(t, glm::dot(litNormal, windingNormal) > 0.f);
}

glm::vec2 ReflectionScattering::widths(uint32_t t, const glm::vec3& u, const glm::vec3& v) const {
  const Moment& m = moments_[reflectors_.surfaceOf(t)];
  // u^T (R C R^T) u = (R^T u)^T C (R^T u): the moment stays in its mesh's frame.
  const glm::mat3 toLocal = m.object < 0 ? glm::mat3(1.f) : glm::transpose(rotation_[m.object]);
  const glm::vec3 lu = toLocal * u, lv = toLocal * v;
  return {std::sqrt(std::max(0.f, 12.f * glm::dot(lu, m.c * lu))),
          std::sqrt(std::max(0.f, 12.f * glm::dot(lv, m.c * lv)))};
}

Bands ReflectionScattering::specularShare(uint32_t t, const glm::vec3& incoming,
                                          const glm::vec3& litNormal, float before, float after,
                                          float speedOfSound) const {
  const double d1 = before, d2 = after;
  const double L = std::isinf(d2) ? d1 : d1 * d2 / (d1 + d2);
  Bands out(1.f);
  if (!(L > 0.0) || !(speedOfSound > 0.f)) return out;
  const SmallReflectors::Zone zone = SmallReflectors::zoneOf(
      glm::dvec3(0.0), glm::dvec3(litNormal), glm::dvec3(incoming), d1, std::isinf(d2) ? 1.0 : d2);
  const glm::vec2 w = widths(t, glm::vec3(zone.u), glm::vec3(zone.v));
  const double a = double(w.x) * zone.cosIncidence, b = double(w.y);  // projected widths, m
  for (int k = 0; k < kNumBands; ++k) {
    const double zoneArea = speedOfSound / kBandCentreHz[k] * L;  // lambda L, m^2
    out[k] = float(std::min(1.0, a * a / zoneArea) * std::min(1.0, b * b / zoneArea));
  }
  return out;
}

bool ReflectionScattering::scatters(const Tracer& tracer, std::span<const ListenerSphere> receivers,
                                    const Reflection& r, float speedOfSound, const Bands& s,
                                    int band, float u, Bands& energy) const {
  constexpr float kFar = std::numeric_limits<float>::infinity();
  const int b = std::max(band, 0);
  // K is least at the largest L, and L <= d1: where even that keeps every band, no query.
  if (specularShare(r.triangle, r.incoming, r.litNormal, r.before, kFar, speedOfSound).min() >= 1.f)
    return u < s[b];
  SurfaceHit next;
  const float surface = tracer.intersect(TraceRay{r.point, r.mirrored}, next) ? next.t : kFar;
  const float after = nearestReceiver(receivers, r.point, r.mirrored, surface);
  const Bands keep = (Bands(1.f) - s) * specularShare(r.triangle, r.incoming, r.litNormal, r.before,
                                                      after, speedOfSound);
  if (band >= 0) return u >= keep[b];
  const float specular = keep.sum() / float(kNumBands);
  const bool diffuse = u >= specular;
  energy *= diffuse ? (Bands(1.f) - keep) * (1.f / (1.f - specular)) : keep * (1.f / specular);
  return diffuse;
}

}  // namespace dpc
