#include "bake/probe_grid.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <glm/vector_relational.hpp>
#include <sstream>
#include <glm/geometric.hpp>

#include "common/input_error.h"
#include "common/input_file.h"
#include "engine/embree_tracer.h"
#include "engine/setup_check.h"

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

ProbeGrid placeProbes(const SceneDesc& scene, const std::vector<glm::vec3>& candidates,
                      float radius, const std::string& sceneFile, const std::string& field) {
  const EmbreeTracer tracer(scene.mesh);
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
  std::vector<glm::vec3> candidates;
  const float y = float(lo.y + request.heightM);
  for (size_t j = 0; j < size_t(nz); ++j)
    for (size_t i = 0; i < size_t(nx); ++i)
      candidates.emplace_back(float(lo.x + (double(i) + 0.5) * request.spacingM), y,
                              float(lo.z + (double(j) + 0.5) * request.spacingM));
  return placeProbes(scene, candidates, request.radiusM, sceneFile, "--spacing/--height");
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
