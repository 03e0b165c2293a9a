#include "apps/bake/probe_grid.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "common/input_error.h"
#include "engine/embree_tracer.h"
#include "engine/setup_check.h"

namespace dpc::bake {
namespace {

enum class Placement { kKept, kOutside, kInsideGeometry, kNearSurface };

/// Direction i of n on a Fibonacci sphere (the setup check's directions).
glm::vec3 fibonacci(int i, int n) {
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  const double y = 1.0 - 2.0 * (i + 0.5) / n;
  const double r = std::sqrt(1.0 - y * y);
  return {float(r * std::cos(golden * i)), float(y), float(r * std::sin(golden * i))};
}

/// Surfaces a ray from p along d crosses (kMaxCrossings + 1 when it never leaves).
int crossings(const Tracer& tracer, const glm::vec3& p, const glm::vec3& d) {
  int count = 0;
  float t = 0.f;
  SurfaceHit hit;
  while (count <= kMaxCrossings && tracer.intersect(TraceRay{p, d, t, 1e30f}, hit)) {
    ++count;
    t = hit.t + 1e-4f;
  }
  return count;
}

Placement place(const Tracer& tracer, const glm::vec3& p, float radius) {
  float nearest = 1e30f;
  for (int i = 0; i < kSetupCheckDirections; ++i) {
    SurfaceHit hit;
    if (!tracer.intersect(TraceRay{p, fibonacci(i, kSetupCheckDirections), 0.f, 1e30f}, hit))
      return Placement::kOutside;
    nearest = std::min(nearest, hit.t);
  }
  // An irrational direction, so the ray does not run along the edges of axis-aligned walls.
  const int n = crossings(tracer, p, glm::normalize(glm::vec3(0.5377f, 0.2113f, 0.8161f)));
  if (n > kMaxCrossings) return Placement::kOutside;
  if (n % 2 == 0) return Placement::kInsideGeometry;
  if (nearest < radius * (1.f - 1e-4f)) return Placement::kNearSurface;
  return Placement::kKept;
}

void count(ProbeGrid& grid, Placement p, const glm::vec3& position) {
  switch (p) {
    case Placement::kKept: grid.positions.push_back(position); break;
    case Placement::kOutside: ++grid.outside; break;
    case Placement::kInsideGeometry: ++grid.insideGeometry; break;
    case Placement::kNearSurface: ++grid.nearSurface; break;
  }
}

}  // namespace

ProbeGrid makeProbeGrid(const SceneDesc& scene, const GridRequest& request,
                        const std::string& sceneFile) {
  if (!(request.spacingM > 0.0) || !std::isfinite(request.spacingM))
    throw InputError("command line", "--spacing",
                     std::to_string(request.spacingM) + " m is not > 0");
  glm::vec3 lo(1e30f), hi(-1e30f);
  for (const glm::vec3& v : scene.mesh.vertices) {
    lo = glm::min(lo, v);
    hi = glm::max(hi, v);
  }
  const double nx = std::floor((hi.x - lo.x) / request.spacingM);
  const double nz = std::floor((hi.z - lo.z) / request.spacingM);
  if (!(nx * nz <= double(kMaxGridCandidates)))
    throw InputError("command line", "--spacing",
                     std::to_string(request.spacingM) + " m gives more than " +
                         std::to_string(kMaxGridCandidates) + " grid points");
  const EmbreeTracer tracer(scene.mesh);
  ProbeGrid grid;
  const float y = float(lo.y + request.heightM);
  for (size_t j = 0; j < size_t(nz); ++j)
    for (size_t i = 0; i < size_t(nx); ++i) {
      const glm::vec3 p(float(lo.x + (double(i) + 0.5) * request.spacingM), y,
                        float(lo.z + (double(j) + 0.5) * request.spacingM));
      count(grid, place(tracer, p, request.radiusM), p);
      ++grid.candidates;
    }
  if (grid.positions.empty())
    throw InputError(sceneFile, "--spacing/--height",
                     "no valid probe among " + std::to_string(grid.candidates) +
                         " grid points (" + std::to_string(grid.outside) + " outside, " +
                         std::to_string(grid.insideGeometry) + " inside geometry, " +
                         std::to_string(grid.nearSurface) + " near a surface)");
  return grid;
}

}  // namespace dpc::bake
