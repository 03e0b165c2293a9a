#include "engine/specular_paths.h"

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>
#include <numbers>
#include <utility>

#include "common/random.h"
#include "engine/channel_path.h"
#include "engine/patch.h"
#include "engine/reflection_scattering.h"

namespace dpc {

namespace {

/// Barycentric tolerance of the inside test: a reflection point this far outside its triangle
/// (as a fraction of the triangle) still counts, so a path across the shared edge of two
/// triangles is not lost to rounding; the duplicate this can give is removed afterwards.
constexpr double kInsideTolerance = 1e-6;

using Plane = FacePlane;

bool planeOf(const glm::dvec3& v0, const glm::dvec3& v1, const glm::dvec3& v2, Plane& p) {
  const glm::dvec3 c = glm::cross(v1 - v0, v2 - v0);
  const double len = glm::length(c);
  if (!(len > 0.0)) return false;  // degenerate triangle: no plane
  p.n = c / len;
  p.d = glm::dot(p.n, v0);
  return true;
}

/// True when q (on the triangle's plane) lies inside triangle (v0, v1, v2), within
/// kInsideTolerance in barycentric coordinates.
bool inside(const glm::dvec3& q, const glm::dvec3& v0, const glm::dvec3& v1, const glm::dvec3& v2) {
  const glm::dvec3 e1 = v1 - v0, e2 = v2 - v0, w = q - v0;
  const double d11 = glm::dot(e1, e1), d12 = glm::dot(e1, e2), d22 = glm::dot(e2, e2);
  const double w1 = glm::dot(w, e1), w2 = glm::dot(w, e2);
  const double det = d11 * d22 - d12 * d12;
  if (!(det > 0.0)) return false;
  const double u = (d22 * w1 - d12 * w2) / det;
  const double v = (d11 * w2 - d12 * w1) / det;
  return u >= -kInsideTolerance && v >= -kInsideTolerance && u + v <= 1.0 + kInsideTolerance;
}

/// The static mesh, then each object's mesh.
std::vector<const Mesh*> meshesOf(const Mesh& mesh, const std::vector<ObjectDesc>& objects) {
  std::vector<const Mesh*> out{&mesh};
  for (const ObjectDesc& o : objects) out.push_back(&o.mesh);
  return out;
}

}  // namespace

void addSpecularPaths(const std::vector<SpecularPath>& paths, EnergyResponse& response,
                      ArrivalSink* directional) {
  for (const SpecularPath& p : paths) {
    response.add(p.delaySeconds, p.intensity);
    if (directional) directional->add(p.delaySeconds, p.intensity, p.direction);
  }
}

uint64_t SpecularSequence::key() const {
  uint64_t h = mix64(0x5bec0a7e1ade0001ULL + order);
  for (uint32_t i = 0; i < order; ++i) h = pathHashAddPatch(h, triangles[i]);
  return h;
}

SpecularSequence SpecularSequence::prefix(uint32_t k) const {
  SpecularSequence s;
  s.order = k;
  std::copy_n(triangles.begin(), k, s.triangles.begin());
  return s;
}

SpecularCandidates::SpecularCandidates(size_t capacity) : capacity_(capacity) {
  sequences_.reserve(capacity_);
  index_.reserve(capacity_);
}

void SpecularCandidates::clear() {
  sequences_.clear();
  index_.clear();
  overflow_ = 0;
}

bool SpecularCandidates::insert(const SpecularSequence& sequence) {
  const uint64_t key = sequence.key();
  if (index_.find(key) != index_.end()) return true;
  if (sequences_.size() >= capacity_) {
    ++overflow_;
    return false;
  }
  index_.emplace(key, uint32_t(sequences_.size()));
  sequences_.push_back(sequence);
  return true;
}

SpecularScene::SpecularScene(const Mesh& mesh, const std::vector<ObjectDesc>& objects,
                             const Geometry& geometry, const Tracer& tracer,
                             const Bands& airPerMetre, float speedOfSound,
                             const ReflectionScattering* smallFaces)
    : faces_(meshesOf(mesh, objects)),
      smallFaces_(smallFaces),
      geometry_(geometry),
      tracer_(tracer),
      airPerMetre_(airPerMetre),
      speedOfSound_(speedOfSound) {
  auto trianglesOf = [](const Mesh& m) {
    std::vector<Triangle> t;
    t.reserve(m.triangles.size());
    for (const auto& tri : m.triangles)
      t.push_back({m.vertices[tri[0]], m.vertices[tri[1]], m.vertices[tri[2]]});
    return t;
  };
  world_ = trianglesOf(mesh);
  for (const ObjectDesc& o : objects) {
    objectFirst_.push_back(uint32_t(world_.size()));
    local_.push_back(trianglesOf(o.mesh));
    world_.insert(world_.end(), local_.back().begin(), local_.back().end());
  }
  for (size_t k = 0; k < objects.size(); ++k) {
    const auto& key = objects[k].trajectory;
    setObjectPose(k, key.empty() ? Pose{} : Pose{key.front().position, key.front().rotation});
  }
}

void SpecularScene::setObjectPose(size_t object, const Pose& pose) {
  if (object >= local_.size()) return;
  const glm::mat3 r = glm::mat3_cast(pose.rotation);
  Triangle* out = world_.data() + objectFirst_[object];
  for (const Triangle& t : local_[object])
    *out++ = {r * t.v0 + pose.position, r * t.v1 + pose.position, r * t.v2 + pose.position};
}

bool SpecularScene::mirror(const SpecularSequence& seq, const glm::dvec3& source,
                           std::array<Plane, kMaxExactOrder>& planes,
                           std::array<glm::dvec3, kMaxExactOrder + 1>& images) const {
  const uint32_t k = seq.order;
  if (k < 1 || k > uint32_t(kMaxExactOrder)) return false;
  images[0] = source;
  for (uint32_t i = 0; i < k; ++i) {
    if (seq.triangles[i] >= world_.size()) return false;
    const Triangle& t = world_[seq.triangles[i]];
    if (!planeOf(t.v0, t.v1, t.v2, planes[i])) return false;
    const double dist = glm::dot(planes[i].n, images[i]) - planes[i].d;
    if (std::abs(dist) < 1e-9) return false;  // the previous image lies on the plane
    images[i + 1] = images[i] - 2.0 * dist * planes[i].n;
  }
  return true;
}

bool SpecularScene::imageOf(const SpecularSequence& seq, const glm::vec3& source,
                            glm::dvec3& image) const {
  std::array<Plane, kMaxExactOrder> planes;
  std::array<glm::dvec3, kMaxExactOrder + 1> images;
  if (!mirror(seq, source, planes, images)) return false;
  image = images[seq.order];
  return true;
}

bool SpecularScene::construct(const SpecularSequence& seq, const glm::dvec3& source,
                              const glm::dvec3& listener, SpecularPath& path,
                              glm::dvec3& image) const {
  const uint32_t k = seq.order;
  std::array<Plane, kMaxExactOrder> planes;
  std::array<glm::dvec3, kMaxExactOrder + 1> images;  // S_0 .. S_k
  if (!mirror(seq, source, planes, images)) return false;
  glm::dvec3 p = listener;  // P_{i+1}, starting at the listener
  for (uint32_t i = k; i-- > 0;) {
    const Plane& pl = planes[i];
    const double a = glm::dot(pl.n, p) - pl.d;              // listener-side point
    const double b = glm::dot(pl.n, images[i + 1]) - pl.d;  // image S_{i+1} (1-based: S_i)
    // Opposite sides, strictly: the crossing lies between the two ends, and P_{i+1} is on the
    // side the sound arrives from (the side of the previous image).
    if (!(a * b < 0.0)) return false;
    const glm::dvec3 q = p + (a / (a - b)) * (images[i + 1] - p);
    if (!insideFace(q, seq.triangles[i])) return false;
    path.points[i] = glm::vec3(q);
    p = q;
  }
  image = images[k];
  return true;
}

bool SpecularScene::insideFace(const glm::dvec3& q, uint32_t face) const {
  for (uint32_t t : faces_.triangles(face)) {
    const Triangle& tri = world_[t];
    if (inside(q, tri.v0, tri.v1, tri.v2)) return true;
  }
  return false;
}

namespace {

/// Segment i (0 .. order) of the path S -> P1 -> ... -> Pk -> L: its two ends.
std::pair<glm::vec3, glm::vec3> segmentEnds(const SpecularPath& path, const glm::vec3& source,
                                            const glm::vec3& listener, uint32_t i) {
  return {i == 0 ? source : path.points[i - 1], i == path.order ? listener : path.points[i]};
}

}  // namespace

bool SpecularScene::visible(const SpecularPath& path, const glm::vec3& source,
                            const glm::vec3& listener) const {
  // Ends on a surface keep surfaceOffset() clear of it.
  for (uint32_t i = 0; i <= path.order; ++i) {
    const auto [a, b] = segmentEnds(path, source, listener, i);
    const glm::vec3 ab = b - a;
    const float len = glm::length(ab);
    const float tnear = i == 0 ? 0.f : surfaceOffset(a, len);
    const float tfar = i == path.order ? len : len - surfaceOffset(b, len);
    if (!(tfar > tnear)) return false;  // reflection points (nearly) coincide
    if (tracer_.occluded(TraceRay{a, ab / len, tnear, tfar})) return false;
  }
  for (uint32_t i = 0; i < path.order; ++i)
    if (turnBlocked(segmentEnds(path, source, listener, i).first, path.points[i],
                    segmentEnds(path, source, listener, i + 1).second))
      return false;
  return true;
}

bool SpecularScene::turnBlocked(const glm::vec3& from, const glm::vec3& point,
                                const glm::vec3& to) const {
  // The legs' tests stop surfaceOffset() short of the point, so a surface through it (a
  // partition whose foot the point is on) crosses neither leg. It crosses the chord between
  // the legs near the point: the chord joins two free points on the lit side, so it stays in
  // the lit half-space, and within the triangle (chord, point) only such a surface lies.
  const float before = glm::distance(from, point), after = glm::distance(point, to);
  const float d = std::min({kTurnChord, 0.25f * before, 0.25f * after});
  if (!(d > 0.f)) return false;
  const glm::vec3 a = point + (from - point) * (d / before);
  const glm::vec3 b = point + (to - point) * (d / after);
  const float length = glm::distance(a, b);
  return length > 0.f && tracer_.occluded(TraceRay{a, (b - a) / length, 0.f, length});
}

bool SpecularScene::facedWithin(const glm::vec3& point, uint32_t face, const glm::vec3& from) const {
  const Triangle& t = world_[face];
  glm::vec3 n = glm::cross(t.v1 - t.v0, t.v2 - t.v0);
  const float length = glm::length(n);
  if (!(length > 0.f)) return false;
  n /= glm::dot(n, from - point) < 0.f ? -length : length;  // toward the side the path is on
  return tracer_.occluded(TraceRay{point, n, surfaceOffset(point), 2.f * kChannelGapMax});
}

bool SpecularScene::segmentInGap(const glm::vec3& a, const glm::vec3& b, uint32_t aFace,
                                 uint32_t bFace) const {
  // Near a reflection point its own face blocks the parallel on one side, and a face beside
  // it (a room's corner) the other: those ends are left to facedWithin, and a parallel that
  // crosses an end's own face further on (a short leg between a floor and a wall) goes on.
  const bool aOnSurface = aFace != kNoFace, bOnSurface = bFace != kNoFace;
  const float margin = 2.f * kChannelGapMax, length = glm::distance(a, b);
  const float from = aOnSurface ? margin : 0.f, to = length - (bOnSurface ? margin : 0.f);
  if (!(to - from > kChannelGapMax)) return false;
  const glm::vec3 u = (b - a) / length;
  const glm::vec3 n1 = glm::normalize(
      glm::cross(u, std::abs(u.x) < 0.7f ? glm::vec3(1.f, 0.f, 0.f) : glm::vec3(0.f, 1.f, 0.f)));
  auto blocked = [&](const glm::vec3& origin, float& t) {
    TraceRay ray{origin, u, from, to};
    for (int k = 0; k < 3; ++k) {  // past the ends' own faces
      SurfaceHit hit;
      if (!tracer_.intersect(ray, hit)) return false;
      const uint32_t f = faces_.faceOf(hit.triangle);
      if (f != aFace && f != bFace) {
        t = hit.t;
        return true;
      }
      ray.tnear = hit.t + surfaceOffset(origin + hit.t * u, hit.t);
    }
    return false;
  };
  for (const glm::vec3& n : {n1, glm::cross(u, n1)}) {
    float near = 0.f, far = 0.f;
    if (blocked(a + kChannelGapMax * n, near) && blocked(a - kChannelGapMax * n, far) &&
        std::abs(near - far) <= kChannelDepthMax)
      return true;
  }
  return false;
}

bool SpecularScene::inGap(const SpecularPath& path, const glm::vec3& source,
                          const glm::vec3& listener) const {
  for (uint32_t i = 0; i <= path.order; ++i) {
    const auto [a, b] = segmentEnds(path, source, listener, i);
    if (i < path.order && facedWithin(b, path.triangles[i], a)) return true;
    if (segmentInGap(a, b, i > 0 ? path.triangles[i - 1] : kNoFace,
                     i < path.order ? path.triangles[i] : kNoFace))
      return true;
  }
  return false;
}

bool SpecularScene::validate(const SpecularSequence& seq, const glm::vec3& source,
                             const glm::vec3& listener, float radius, SpecularPath& path,
                             bool* throughGap) const {
  if (throughGap) *throughGap = false;
  path.order = seq.order;
  glm::dvec3 image;
  if (!construct(seq, source, listener, path, image)) return false;
  path.triangles = seq.triangles;
  if (!visible(path, source, listener)) return false;
  if (inGap(path, source, listener)) {
    if (throughGap) *throughGap = true;
    return false;
  }
  const double length = glm::length(glm::dvec3(listener) - image);
  path.key = seq.key();
  std::fill(path.points.begin() + seq.order, path.points.end(), glm::vec3(0.f));  // unused
  path.length = float(length);
  path.delaySeconds = length / double(speedOfSound_);
  const glm::vec3 toLast = path.points[seq.order - 1] - listener;
  const float toLastLength = glm::length(toLast);
  path.direction = toLastLength > 0.f ? toLast / toLastLength : glm::vec3(0.f);
  Bands factor(1.f);
  if (smallFaces_ && seq.order == 1)
    factor = smallFaces_->reflectors().firstOrderShare(
        tracer_, world_, seq.triangles[0], path.points[0], source, length, double(speedOfSound_));
  else if (smallFaces_)
    factor =
        smallFaces_->pathShare(tracer_, world_, {seq.triangles.data(), seq.order},
                               {path.points.data(), seq.order}, source, listener, speedOfSound_);
  for (uint32_t i = 0; i < seq.order; ++i)
    factor *= geometry_.reflectance(seq.triangles[i]) *
              (Bands(1.f) - geometry_.scattering(seq.triangles[i]));
  const float spread = std::max(float(length), 0.5f * radius);
  path.intensity = factor * exp(airPerMetre_ * -float(length)) *
                   (1.f / (4.f * std::numbers::pi_v<float> * spread * spread));
  return true;
}

}  // namespace dpc
