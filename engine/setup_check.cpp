#include "engine/setup_check.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

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

std::vector<std::string> setupWarnings(const SceneDesc& scene) {
  std::vector<std::string> out;
  if (scene.mesh.materialIndex.empty()) return out;
  const EmbreeTracer tracer(scene.mesh);
  struct Point {
    std::string what;
    glm::vec3 p;
    Seen seen;
    float radius;  ///< listener sphere radius; 0 for sources
  };
  std::vector<Point> points;
  for (const ListenerDesc& l : scene.listeners)
    points.push_back({"listener '" + l.name + "'", listenerPositionAt(l, 0.0), {}, l.radius});
  for (const SourceDesc& s : scene.sources)
    points.push_back({"source '" + s.name + "'", sourcePositionAt(s, 0.0), {}, 0.f});
  size_t enclosed = 0;
  for (Point& pt : points) {
    pt.seen = look(tracer, pt.p);
    enclosed += pt.seen.escaped == 0;
    if (pt.radius <= 0.f) continue;
    for (int axis = 0; axis < 3; ++axis)
      for (float sign : {-1.f, 1.f}) {
        glm::vec3 q = pt.p;
        q[axis] += sign * kOffPoint;
        pt.seen.nearest = std::min(pt.seen.nearest, look(tracer, q).nearest + kOffPoint);
      }
  }
  for (const Point& pt : points) {
    const std::string at = pt.what + fmt(" at (%g, %g, %g)", pt.p.x, pt.p.y, pt.p.z);
    if (enclosed > 0 && pt.seen.escaped > 0)
      out.push_back(scene.path + ": " + at + ": " + std::to_string(pt.seen.escaped) + " of " +
                    std::to_string(kSetupCheckDirections) +
                    " rays from it escape while other points are enclosed: is it outside the "
                    "room?");
    if (pt.radius <= 0.f || pt.seen.escaped == kSetupCheckDirections) continue;
    if (pt.seen.escaped == 0 && pt.radius >= pt.seen.farthest)
      out.push_back(scene.path + ": " + at + ": radius " + fmt("%g", pt.radius) +
                    " m is larger than the room (farthest surface " +
                    fmt("%.2f", pt.seen.farthest) + " m): the sphere holds every path");
    else if (pt.radius > pt.seen.nearest)
      out.push_back(scene.path + ": " + at + ": radius " + fmt("%g", pt.radius) +
                    " m reaches through a surface " + fmt("%.2f", pt.seen.nearest) +
                    " m away: paths on both sides of it are counted");
    else if (pt.radius < kTinyRadiusFraction * pt.seen.nearest)
      out.push_back(scene.path + ": " + at + ": radius " + fmt("%g", pt.radius) +
                    " m is tiny against the nearest surface " + fmt("%.2f", pt.seen.nearest) +
                    " m away: rays hit a sphere in proportion to its area, so its responses "
                    "will be nearly or entirely empty (0.1 to 1 m is usual)");
  }
  return out;
}

}  // namespace dpc
