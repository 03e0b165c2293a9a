#include "engine/setup_check.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vector_relational.hpp>

#include "common/sphere_quadrature.h"
#include "engine/embree_tracer.h"
#include "scene/trajectory.h"

namespace dpc {

namespace {

struct Seen {
  int escaped = 0;        ///< directions that hit nothing
  float nearest = 1e30f;  ///< metres to the nearest hit
  float farthest = 0.f;   ///< metres to the farthest hit
};

/// How far a surface through the point itself can hide: a ray starting on a sheet's plane
/// does not hit the sheet, so the nearest surface is also looked for from this far either side
/// of the point along each axis (a listener's centre in a closed door leaf's plane went
/// unwarned and read 14.5 dB above the free field).
constexpr float kOffPoint = 0.01f;  // m

Seen look(const Tracer& tracer, const glm::vec3& p) {
  Seen s;
  for (int i = 0; i < kSetupCheckDirections; ++i) {
    const glm::vec3 d = setupCheckDirection(i);
    SurfaceHit hit;
    if (!tracer.intersect(TraceRay{p, d, 0.f, 1e30f}, hit)) {
      ++s.escaped;
      continue;
    }
    s.nearest = std::min(s.nearest, hit.t);
    s.farthest = std::max(s.farthest, hit.t);
  }
  return s;
}

std::string fmt(const char* f, double a, double b = 0, double c = 0) {
  char buf[160];
  std::snprintf(buf, sizeof buf, f, a, b, c);
  return buf;
}

}  // namespace

glm::vec3 setupCheckDirection(int i) {
  const std::array<double, 3> p = fibonacciPoint(i, kSetupCheckDirections);  // z up
  return {float(p[0]), float(p[2]), float(p[1])};                            // y up
}

namespace {

/// A point the check looks from: a listener's or source's position at one time.
struct Point {
  std::string what;  ///< "listener 'a'"
  size_t owner;      ///< which listener or source (listeners first)
  double time;       ///< seconds
  glm::vec3 p;
  float radius;  ///< listener sphere radius; 0 for sources
  Seen seen{};
  std::string at() const {
    return what + fmt(" at (%g, %g, %g)", p.x, p.y, p.z) +
           (time != 0.0 ? fmt(" (t = %g s)", time) : std::string());
  }
};

/// The times a trajectory is checked at: 0 and its keyframes' (at most kMaxCheckedKeyframes,
/// spread evenly over them): a keyframe through a wall is as wrong as a start there.
constexpr size_t kMaxCheckedKeyframes = 32;
std::vector<double> checkedTimes(const std::vector<Keyframe>& keys) {
  std::vector<double> t{0.0};
  const size_t step = std::max<size_t>(1, (keys.size() + kMaxCheckedKeyframes - 1) /
                                              kMaxCheckedKeyframes);
  for (size_t k = 0; k < keys.size(); k += step)
    if (keys[k].timeSeconds > 0.0) t.push_back(keys[k].timeSeconds);
  return t;
}

std::vector<Point> checkedPoints(const SceneDesc& scene) {
  std::vector<Point> points;
  size_t owner = 0;
  for (const ListenerDesc& l : scene.listeners) {
    for (double t : checkedTimes(l.trajectory))
      points.push_back({"listener '" + l.name + "'", owner, t, listenerPositionAt(l, t), l.radius});
    ++owner;
  }
  for (const SourceDesc& s : scene.sources) {
    for (double t : checkedTimes(s.trajectory))
      points.push_back({"source '" + s.name + "'", owner, t, sourcePositionAt(s, t), 0.f});
    ++owner;
  }
  return points;
}

/// Looks from each point; a listener's nearest surface also from kOffPoint either side.
void lookFromEach(const Tracer& tracer, std::vector<Point>& points) {
  for (Point& pt : points) {
    pt.seen = look(tracer, pt.p);
    if (pt.radius <= 0.f) continue;
    for (int axis = 0; axis < 3; ++axis)
      for (float sign : {-1.f, 1.f}) {
        glm::vec3 q = pt.p;
        q[axis] += sign * kOffPoint;
        pt.seen.nearest = std::min(pt.seen.nearest, look(tracer, q).nearest + kOffPoint);
      }
  }
}

/// The sphere's warnings at one point (larger than the room, through a surface, tiny).
void sphereWarnings(const SceneDesc& scene, const Point& pt, std::vector<std::string>& out) {
  if (pt.radius <= 0.f || pt.seen.escaped == kSetupCheckDirections) return;
  const std::string head = scene.path + ": " + pt.at() + ": radius " + fmt("%g", pt.radius);
  if (pt.seen.escaped == 0 && pt.radius >= pt.seen.farthest)
    out.push_back(head + " m is larger than the room (farthest surface " +
                  fmt("%.2f", pt.seen.farthest) + " m): the sphere holds every path");
  else if (pt.radius > pt.seen.nearest)
    out.push_back(head + " m reaches through a surface " + fmt("%.2f", pt.seen.nearest) +
                  " m away: paths on both sides of it are counted");
  else if (pt.radius < kTinyRadiusFraction * pt.seen.nearest)
    out.push_back(head + " m is tiny against the nearest surface " + fmt("%.2f", pt.seen.nearest) +
                  " m away: rays hit a sphere in proportion to its area, so its responses "
                  "will be nearly or entirely empty (0.1 to 1 m is usual)");
}

/// Points outside the room while others are enclosed (the first time of each listener or
/// source only), or every point outside the mesh's bounds (an export's units or offset).
void outsideWarnings(const SceneDesc& scene, const std::vector<Point>& points,
                     std::vector<std::string>& out) {
  const size_t enclosed = size_t(std::count_if(
      points.begin(), points.end(), [](const Point& pt) { return pt.seen.escaped == 0; }));
  std::vector<bool> warned(scene.listeners.size() + scene.sources.size(), false);
  for (const Point& pt : points) {
    if (enclosed == 0 || pt.seen.escaped == 0 || warned[pt.owner]) continue;
    warned[pt.owner] = true;
    out.push_back(scene.path + ": " + pt.at() + ": " + std::to_string(pt.seen.escaped) + " of " +
                  std::to_string(kSetupCheckDirections) +
                  " rays from it escape while other points are enclosed: is it outside the "
                  "room?");
  }
  glm::vec3 lo(1e30f), hi(-1e30f);
  for (const glm::vec3& v : scene.mesh.vertices) lo = glm::min(lo, v), hi = glm::max(hi, v);
  // Within the mesh's own size of its box: a listener above a flat ground plane is not
  // outside, a mesh in centimetres read as metres (100 times too small) is.
  const glm::vec3 reach(glm::length(hi - lo));
  const bool anyNear = std::any_of(points.begin(), points.end(), [&](const Point& pt) {
    return glm::all(glm::greaterThanEqual(pt.p, lo - reach)) &&
           glm::all(glm::lessThanEqual(pt.p, hi + reach));
  });
  if (!points.empty() && !anyNear)
    out.push_back(scene.path + ": mesh: every listener and source lies far outside its bounds " +
                  fmt("(%g, %g, %g)", lo.x, lo.y, lo.z) +
                  fmt(" to (%g, %g, %g)", hi.x, hi.y, hi.z) +
                  ": are the mesh's units or offset those of the scene's positions?");
}

/// A source inside a listener's sphere at time 0: its direct sound is read at R/2 (the
/// distance is clamped there), whatever its true distance.
void insideSphereWarnings(const SceneDesc& scene, std::vector<std::string>& out) {
  for (const ListenerDesc& l : scene.listeners)
    for (const SourceDesc& s : scene.sources) {
      const float d = glm::length(sourcePositionAt(s, 0.0) - listenerPositionAt(l, 0.0));
      if (d < l.radius)
        out.push_back(scene.path + ": source '" + s.name + "' lies " + fmt("%.3g", d) +
                      " m from listener '" + l.name + "', inside its " + fmt("%g", l.radius) +
                      " m sphere: its direct sound is read as at " + fmt("%g", 0.5 * l.radius) +
                      " m (R/2), and its rays start inside the sphere");
    }
}

}  // namespace

std::vector<std::string> setupWarnings(const SceneDesc& scene) {
  std::vector<std::string> out;
  if (scene.mesh.materialIndex.empty()) return out;
  const EmbreeTracer tracer(scene.mesh);
  std::vector<Point> points = checkedPoints(scene);
  lookFromEach(tracer, points);
  outsideWarnings(scene, points, out);
  for (const Point& pt : points)
    if (pt.time == 0.0) sphereWarnings(scene, pt, out);
  insideSphereWarnings(scene, out);
  return out;
}

}  // namespace dpc
