#include "bake/probe_grid.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <glm/geometric.hpp>
#include <glm/vector_relational.hpp>
#include <sstream>

#include "common/input_error.h"
#include "common/input_file.h"
#include "engine/embree_tracer.h"
#include "engine/setup_check.h"
#include "scene/limits.h"
#include "scene/validate.h"

namespace dpc::bake {
namespace {

enum class Placement { kKept, kOutside, kInsideGeometry, kNearSurface };

/// +1 when the mesh's normals point into the enclosed air (a room modelled from inside: the
/// signed volume sum v0 . (v1 x v2) / 6 is negative), -1 when they point out of it.
float airSide(const Mesh& mesh) {
  double volume = 0.0;
  for (const auto& t : mesh.triangles)
    volume += glm::dot(glm::dvec3(mesh.vertices[t[0]]),
                       glm::cross(glm::dvec3(mesh.vertices[t[1]]), glm::dvec3(mesh.vertices[t[2]])));
  return volume <= 0.0 ? 1.f : -1.f;
}

/// Whether a surface passes through p (within 1 cm): rays from p meet a sheet that lies in
/// its plane only edge-on, and miss it (a door leaf's plane on a grid line). A segment through
/// p along a direction no mesh is drawn along crosses it.
bool onSheet(const Tracer& tracer, const glm::vec3& p) {
  const glm::vec3 g = glm::normalize(glm::vec3(0.3141f, 0.5772f, 0.7548f));
  constexpr float kReach = 0.01f;
  return tracer.occluded(TraceRay{p - kReach * g, g, 0.f, 2.f * kReach});
}

/// airSide: as airSide(). A point sees the surfaces around it from the air side when it stands
/// in the air; inside a solid (a pillar) most of what it sees is the solid's other side.
Placement place(const Tracer& tracer, const glm::vec3& p, float radius, float airSide) {
  float nearest = 1e30f;
  int facingAir = 0;
  for (int i = 0; i < kSetupCheckDirections; ++i) {
    const glm::vec3 d = setupCheckDirection(i);
    SurfaceHit hit;
    if (!tracer.intersect(TraceRay{p, d, 0.f, 1e30f}, hit)) return Placement::kOutside;
    nearest = std::min(nearest, hit.t);
    if (airSide * glm::dot(d, hit.normal) < 0.f) ++facingAir;
  }
  if (2 * facingAir < kSetupCheckDirections) return Placement::kInsideGeometry;
  if (nearest < radius * (1.f - 1e-4f) || onSheet(tracer, p)) return Placement::kNearSurface;
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

ProbeGrid placeProbes(const SceneDesc& scene, const std::vector<glm::vec3>& candidates,
                      float radius, const std::string& sceneFile, const std::string& field) {
  // Every probe is a point traced from: within the scene's coordinate limit, as every point
  // that reaches Embree (a grid height of 1e20 m aborted inside it).
  for (const glm::vec3& p : candidates)
    for (int k = 0; k < 3; ++k)
      checkField("position", double(p[k]), Origin{sceneFile, {}},
                 field + ": probe coordinate " + "xyz"[k]);
  // Moving objects stand at their first keyframe's pose, where the bake's traces have them.
  const EmbreeTracer tracer(scene.mesh, scene.objects);
  const float side = airSide(scene.mesh);
  ProbeGrid grid;
  for (const glm::vec3& p : candidates) count(grid, place(tracer, p, radius, side), p);
  grid.candidates = candidates.size();
  if (grid.positions.empty())
    throw InputError(sceneFile, field,
                     "no valid probe among " + std::to_string(grid.candidates) +
                         " candidates (" + std::to_string(grid.outside) + " outside, " +
                         std::to_string(grid.insideGeometry) + " inside geometry, " +
                         std::to_string(grid.nearSurface) + " near a surface)");
  return grid;
}

namespace {

void checkBox(const GridRequest& r) {
  for (int a = 0; a < 3; ++a) {
    const float lo = r.boxMin[a], hi = r.boxMax[a];
    if (!std::isfinite(lo) || !std::isfinite(hi) || std::abs(lo) > kMaxCoordinateM ||
        std::abs(hi) > kMaxCoordinateM)
      throw InputError("command line", "--box",
                       "corners must be finite coordinates within +-" +
                           std::to_string(int(kMaxCoordinateM)) + " m");
    if (!(hi > lo)) {
      std::ostringstream m;
      m << "the " << "xyz"[a] << " extent " << hi - lo
        << " m is not > 0 (give x0 y0 z0 x1 y1 z1 with x0 < x1, ...)";
      throw InputError("command line", "--box", m.str());
    }
  }
}

/// The box's lattice points: per axis max(1, floor(extent / spacing)) points, centred.
std::vector<glm::vec3> boxCandidates(const GridRequest& r) {
  checkBox(r);
  std::array<size_t, 3> n{};
  std::array<double, 3> start{};
  double total = 1.0;
  for (int a = 0; a < 3; ++a) {
    const double extent = double(r.boxMax[a]) - double(r.boxMin[a]);
    n[size_t(a)] = size_t(std::max(1.0, std::floor(extent / r.spacingM)));
    start[size_t(a)] = r.boxMin[a] + 0.5 * (extent - double(n[size_t(a)] - 1) * r.spacingM);
    total *= double(n[size_t(a)]);
  }
  if (!(total <= double(kMaxGridCandidates)))
    throw InputError("command line", "--spacing",
                     valueText(r.spacingM) + " m gives more than " +
                         std::to_string(kMaxGridCandidates) + " points in the box");
  std::vector<glm::vec3> c;
  for (size_t k = 0; k < n[1]; ++k)
    for (size_t j = 0; j < n[2]; ++j)
      for (size_t i = 0; i < n[0]; ++i)
        c.emplace_back(float(start[0] + double(i) * r.spacingM),
                       float(start[1] + double(k) * r.spacingM),
                       float(start[2] + double(j) * r.spacingM));
  return c;
}

}  // namespace

std::string probeLayout(const GridRequest& request, bool list) {
  if (list) return "list";
  if (!request.box) return "grid";
  std::ostringstream s;
  s << "box";
  for (const glm::vec3& v : {request.boxMin, request.boxMax}) s << ' ' << v.x << ' ' << v.y << ' ' << v.z;
  return s.str();
}

std::vector<glm::vec3> gridCandidates(const SceneDesc& scene, const GridRequest& request) {
  if (!(request.spacingM > 0.0) || !std::isfinite(request.spacingM))
    throw InputError("command line", "--spacing",
                     valueText(request.spacingM) + " m is not > 0");
  if (request.box) return boxCandidates(request);
  glm::vec3 lo(1e30f), hi(-1e30f);
  for (const glm::vec3& v : scene.mesh.vertices) {
    lo = glm::min(lo, v);
    hi = glm::max(hi, v);
  }
  const double nx = std::floor((hi.x - lo.x) / request.spacingM);
  const double nz = std::floor((hi.z - lo.z) / request.spacingM);
  if (!(nx * nz <= double(kMaxGridCandidates)))
    throw InputError("command line", "--spacing",
                     valueText(request.spacingM) + " m gives more than " +
                         std::to_string(kMaxGridCandidates) + " grid points");
  std::vector<glm::vec3> candidates;
  const float y = float(lo.y + request.heightM);
  for (size_t j = 0; j < size_t(nz); ++j)
    for (size_t i = 0; i < size_t(nx); ++i)
      candidates.emplace_back(float(lo.x + (double(i) + 0.5) * request.spacingM), y,
                              float(lo.z + (double(j) + 0.5) * request.spacingM));
  return candidates;
}

const char* gridField(const GridRequest& request) {
  return request.box ? "--box" : "--spacing/--height";
}

ProbeGrid makeProbeGrid(const SceneDesc& scene, const GridRequest& request,
                        const std::string& sceneFile) {
  return placeProbes(scene, gridCandidates(scene, request), request.radiusM, sceneFile,
                     gridField(request));
}

std::vector<glm::vec3> readProbeList(const std::string& path) {
  checkInputFile(path, kMaxProbeListBytes, path, "", "probe list");
  std::ifstream in(path);
  std::vector<glm::vec3> points;
  std::string line;
  for (size_t n = 1; std::getline(in, line); ++n) {
    if (line.find('#') != std::string::npos) line.erase(line.find('#'));
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream fields(line);
    std::string extra;
    glm::vec3 p;
    if (!(fields >> std::ws).good()) continue;  // blank or comment
    if (!(fields >> p.x >> p.y >> p.z) || (fields >> extra) || !std::isfinite(p.x) ||
        !std::isfinite(p.y) || !std::isfinite(p.z) || glm::any(glm::greaterThan(
                                                            glm::abs(p), glm::vec3(kMaxCoordinateM))))
      throw InputError(path, "line " + std::to_string(n),
                       "expected three finite coordinates x y z in metres");
    points.push_back(p);
    if (points.size() > kMaxGridCandidates)
      throw InputError(path, "line " + std::to_string(n),
                       "more than " + std::to_string(kMaxGridCandidates) + " probes");
  }
  if (points.empty()) throw InputError(path, "", "no probe position");
  return points;
}

}  // namespace dpc::bake
