#include "engine/reflection_scattering.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>
#include <limits>

#include "engine/channel_path.h"
#include "engine/diffraction.h"
#include "engine/diffraction_edges.h"

namespace dpc {
namespace {

constexpr float kFar = std::numeric_limits<float>::infinity();

/// The triangles' vertices in their mesh's frame, Geometry's numbering, and each one's object
/// (-1 for the static mesh).
struct Corners {
  std::vector<std::array<glm::vec3, 3>> triangles;
  std::vector<int32_t> object;
  glm::vec3 normal(uint32_t t) const {
    const auto& c = triangles[t];
    return glm::cross(c[1] - c[0], c[2] - c[0]);  // not normalised: only its sign is read
  }
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

/// The second moment of area over area (m^2) about their centroid of the triangles `members`
/// for which keep(t) holds: a uniform triangle p0 + x e1 + y e2 has Var x = Var y = 1/18 and
/// Cov(x, y) = -1/36, shifted to the common centroid.
template <class Keep>
glm::mat3 momentOf(const Corners& corners, const std::vector<uint32_t>& members, Keep keep) {
  double area = 0.0;
  glm::dmat3 sum{0.0};
  glm::dvec3 first{0.0};
  for (uint32_t t : members) {
    if (t >= corners.triangles.size() || !keep(t)) continue;
    const auto& c = corners.triangles[t];
    const glm::dvec3 p0(c[0]), e1 = glm::dvec3(c[1]) - p0, e2 = glm::dvec3(c[2]) - p0;
    const double a = 0.5 * glm::length(glm::cross(e1, e2));
    const glm::dvec3 g = p0 + (e1 + e2) / 3.0;
    const glm::dmat3 cov = (glm::outerProduct(e1, e1) + glm::outerProduct(e2, e2)) / 18.0 -
                           (glm::outerProduct(e1, e2) + glm::outerProduct(e2, e1)) / 36.0;
    area += a;
    sum += a * (cov + glm::outerProduct(g, g));
    first += a * g;
  }
  if (!(area > 0.0)) return glm::mat3(0.f);
  first /= area;
  return glm::mat3(sum / area - glm::outerProduct(first, first));
}

/// The larger and smaller eigenvalues of the symmetric [[a, b], [b, c]].
glm::vec2 eigenvalues(float a, float b, float c) {
  const float mean = 0.5f * (a + c), r = std::sqrt(0.25f * (a - c) * (a - c) + b * b);
  return {mean + r, std::max(0.f, mean - r)};
}

/// Appends one mesh's triangles' bodies (`surfaces` its flatSurfaces, per triangle) to bodyOf,
/// numbered after those already there, and its bodies' closed flags to closed.
void addBodies(const SurfaceBodies& bodies, const std::vector<uint32_t>& surfaces,
               std::vector<uint32_t>& bodyOf, std::vector<bool>& closed) {
  const uint32_t first = uint32_t(closed.size());
  for (const uint32_t s : surfaces)
    bodyOf.push_back(s < bodies.body.size() && bodies.body[s] < bodies.closed.size()
                         ? first + bodies.body[s]
                         : UINT32_MAX);
  closed.insert(closed.end(), bodies.closed.begin(), bodies.closed.end());
}

}  // namespace

ReflectionScattering::ReflectionScattering(const Mesh& mesh, const std::vector<uint32_t>& surfaces,
                                           const std::vector<DiffractionEdge>& edges,
                                           const SurfaceBodies& bodies,
                                           const std::vector<ObjectDesc>& objects, bool rays)
    : reflectors_(mesh, surfaces, edges, objects),
      rotation_(objects.size(), glm::mat3(1.f)),
      rays_(rays) {
  addBodies(bodies, surfaces, bodyOf_, closed_);
  for (const ObjectDesc& o : objects) {
    const std::vector<uint32_t> objectSurfaces = flatSurfaces(o.mesh);
    addBodies(surfaceBodies(o.mesh, objectSurfaces), objectSurfaces, bodyOf_, closed_);
  }
  const Corners corners = cornersOf(mesh, objects);
  momentOf_.assign(corners.triangles.size(), 0);
  for (uint32_t s = 0; s < reflectors_.surfaceCount(); ++s) {
    const std::vector<uint32_t>& members = reflectors_.trianglesOf(s);
    if (members.empty() || members.front() >= corners.triangles.size()) continue;
    const int32_t object = corners.object[members.front()];
    // A moment per triangle over those facing its way; a large surface's one per side.
    const bool each = members.size() <= kMaxPerTriangle;
    const glm::vec3 side = corners.normal(members.front());
    for (int way = 0; way < (each ? 0 : 2); ++way) {
      const float sign = way == 0 ? 1.f : -1.f;
      moments_.push_back(
          {momentOf(corners, members,
                    [&](uint32_t u) { return sign * glm::dot(corners.normal(u), side) > 0.f; }),
           object});
    }
    for (uint32_t t : members) {
      if (t >= momentOf_.size()) continue;
      const glm::vec3 n = corners.normal(t);
      if (!each) {
        momentOf_[t] = uint32_t(moments_.size() - (glm::dot(n, side) > 0.f ? 2 : 1));
        continue;
      }
      momentOf_[t] = uint32_t(moments_.size());
      moments_.push_back(
          {momentOf(corners, members,
                    [&](uint32_t u) { return glm::dot(corners.normal(u), n) > 0.f; }),
           object});
    }
  }
  if (moments_.empty()) moments_.push_back({});
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

glm::vec2 ReflectionScattering::zoneWidths(uint32_t t, const glm::vec3& incoming,
                                           const glm::vec3& litNormal) const {
  if (t >= momentOf_.size()) return glm::vec2(0.f);
  const Moment& m = moments_[momentOf_[t]];
  const SmallReflectors::Zone zone = SmallReflectors::zoneOf(glm::dvec3(0.0), glm::dvec3(litNormal),
                                                             glm::dvec3(incoming), 1.0, 1.0);
  // u^T (R C R^T) u = (R^T u)^T C (R^T u): the moment stays in its mesh's frame.
  const glm::mat3 toLocal = m.object < 0 ? glm::mat3(1.f) : glm::transpose(rotation_[m.object]);
  const glm::vec3 u = toLocal * glm::vec3(zone.u), v = toLocal * glm::vec3(zone.v);
  const float cosine = float(zone.cosIncidence);
  const glm::vec2 e = eigenvalues(cosine * cosine * glm::dot(u, m.c * u),
                                  cosine * glm::dot(u, m.c * v), glm::dot(v, m.c * v));
  return glm::sqrt(12.f * e);
}

Bands ReflectionScattering::specularShare(uint32_t t, const glm::vec3& incoming,
                                          const glm::vec3& litNormal, float before, float after,
                                          float speedOfSound) const {
  const double L = double(before) * after / (double(before) + after);
  Bands out(1.f);
  if (!(L > 0.0) || !(speedOfSound > 0.f)) return out;
  const glm::vec2 w = zoneWidths(t, incoming, litNormal);
  const double w1 = double(w.x) * w.x, w2 = double(w.y) * w.y;  // m^2
  for (int k = 0; k < kNumBands; ++k) {
    const double zoneArea = speedOfSound / kBandCentreHz[k] * L;  // lambda L, m^2
    out[k] = float(std::min(1.0, w1 / zoneArea) * std::min(1.0, w2 / zoneArea));
  }
  return out;
}

bool ReflectionScattering::oneClosedBody(uint32_t a, uint32_t b) const {
  if (a >= bodyOf_.size() || b >= bodyOf_.size()) return false;
  const uint32_t body = bodyOf_[a];
  return body == bodyOf_[b] && body < closed_.size() && closed_[body];
}

/// The triangles of other bodies than one closed body's (a TriangleFilter's self).
struct ReflectionScattering::OtherBodies {
  const ReflectionScattering* scattering;
  uint32_t face;
  static bool accepts(const void* self, uint32_t t) {
    const auto* o = static_cast<const OtherBodies*>(self);
    return !o->scattering->oneClosedBody(t, o->face);
  }
};

float ReflectionScattering::backing(const Tracer& tracer, const Reflection& r, float limit) const {
  const float offset = surfaceOffset(r.point);
  glm::vec3 org = r.point - r.litNormal * (2.f * offset);  // just behind the face
  // Behind a closed body's face the first query passes the body itself (its own back, seen
  // from inside): a wall in the plane of that back (a box flush on it) is then met whichever of
  // the two coplanar triangles a plain query would report.
  const OtherBodies others{this, r.triangle};
  const bool closed = oneClosedBody(r.triangle, r.triangle);
  float travelled = 0.f;
  for (int k = 0; k < kBackingHits && travelled < limit; ++k) {
    SurfaceHit hit;
    const TraceRay probe{org, -r.litNormal, 0.f, limit - travelled};
    const TriangleFilter filter{k == 0 && closed ? &OtherBodies::accepts : nullptr, &others};
    if (!tracer.intersect(probe, filter, hit)) break;
    travelled += hit.t;
    const float facing = glm::dot(hit.normal, r.litNormal);
    if (std::abs(facing) < kParallelCos) break;
    // The side the probe meets: a wall if it does not stand free there (a sheet's second copy
    // and another panel do).
    if (!reflectors_.standsFree(hit.triangle, facing > 0.f)) return travelled;
    org -= r.litNormal * (hit.t + offset);
    travelled += offset;
  }
  return kFar;
}

Bands ReflectionScattering::share(const Tracer& tracer, const Reflection& r, float after,
                                  float speedOfSound) const {
  Bands k = specularShare(r.triangle, r.incoming, r.litNormal, r.before, after, speedOfSound);
  if (k.min() >= 1.f) return k;
  SurfaceHit facing;
  if (tracer.intersect(TraceRay{r.point, r.litNormal, 0.f, 2.f * kChannelGapMax}, facing))
    return Bands(1.f);
  const float wall = backing(tracer, r, kBackedWavelengths * speedOfSound / kBandCentreHz[0]);
  for (int b = 0; b < kNumBands; ++b)
    if (wall <= kBackedWavelengths * speedOfSound / kBandCentreHz[b]) k[b] = 1.f;
  return k;
}

uint8_t ReflectionScattering::narrow(const Reflection& r, float speedOfSound, uint8_t carried,
                                     Rng& rng, Bands& energy) const {
  const Bands k = least(r, speedOfSound);
  uint8_t whole = 0;
  for (int b = 0; b < kNumBands; ++b)
    if ((carried >> b & 1u) && k[b] >= 1.f) whole |= uint8_t(1u << b);
  if (whole == carried) return carried;
  // Options: the whole group (|whole| of n chances), or one other band (one chance each).
  const int n = std::popcount(carried), m = std::popcount(whole);
  int pick = std::min(n - 1, int(rng.uniform() * float(n)));
  uint8_t chosen = whole;
  for (int b = 0; b < kNumBands && pick >= m; ++b)
    if ((carried & ~whole) >> b & 1u && pick-- == m) chosen = uint8_t(1u << b);
  const float scale = float(n) / float(std::popcount(chosen));
  for (int b = 0; b < kNumBands; ++b) energy[b] = (chosen >> b & 1u) ? energy[b] * scale : 0.f;
  return chosen;
}

bool ReflectionScattering::scatters(const Tracer& tracer, const Reflection& r, float speedOfSound,
                                    float s, int band, float u) const {
  // K is least at the largest L, d2 = d1: where even that keeps the band, no query.
  if (specularShare(r.triangle, r.incoming, r.litNormal, r.before, r.before, speedOfSound)[band] >=
      1.f)
    return u < s;
  SurfaceHit next;
  const float surface = tracer.intersect(TraceRay{r.point, r.mirrored}, next) ? next.t : kFar;
  const float keep = (1.f - s) * share(tracer, r, std::min(surface, r.before), speedOfSound)[band];
  return u < 1.f - keep;
}

Bands ReflectionScattering::pathShare(const Tracer& tracer, const std::vector<WorldTriangle>& world,
                                      std::span<const uint32_t> triangles,
                                      std::span<const glm::vec3> points, const glm::vec3& source,
                                      const glm::vec3& listener, float speedOfSound) const {
  Bands out(1.f);
  float before = 0.f;
  for (size_t i = 0; rays_ && i < triangles.size() && i < points.size(); ++i) {
    const uint32_t t = triangles[i];
    if (t >= world.size()) continue;
    const glm::vec3 from = i == 0 ? source : points[i - 1];
    const glm::vec3 to = i + 1 < points.size() ? points[i + 1] : listener;
    const float leg = glm::length(points[i] - from);
    before += leg;
    const WorldTriangle& w = world[t];
    const glm::vec3 winding = glm::normalize(glm::cross(w.v1 - w.v0, w.v2 - w.v0));
    const glm::vec3 incoming = (points[i] - from) / std::max(leg, 1e-6f);
    const glm::vec3 lit = glm::dot(winding, incoming) < 0.f ? winding : -winding;
    if (!standsFree(t, lit, winding)) continue;
    const glm::vec3 off = points[i] + lit * surfaceOffset(points[i]);  // as a ray leaves it
    const Reflection r{t, off, incoming, lit, glm::vec3(0.f), before};
    // d2 as the rays take it: the next surface along the outgoing leg, past the listener on
    // the last one, at most d1.
    SurfaceHit next;
    const glm::vec3 outgoing = glm::normalize(to - points[i]);
    const float surface = tracer.intersect(TraceRay{off, outgoing}, next) ? next.t : kFar;
    out *= share(tracer, r, std::min(surface, before), speedOfSound);
  }
  return out;
}

}  // namespace dpc
