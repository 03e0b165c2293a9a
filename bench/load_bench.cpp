// `dpc-bench load`: the load stages of a generated terrain of growing size.
#include "bench/load_bench.h"

#include <chrono>
#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <string>

#include "engine/diffraction.h"
#include "engine/embree_tracer.h"
#include "engine/geometry.h"
#include "testing/temp_dir.h"
#include "testing/terrain.h"

namespace dpc::bench {
namespace {

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

/// The mesh as an OBJ file with one material, "ground".
void writeObj(const Mesh& m, const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) throw std::runtime_error(path + ": cannot write");
  for (const glm::vec3& v : m.vertices) std::fprintf(f, "v %g %g %g\n", v.x, v.y, v.z);
  std::fprintf(f, "usemtl ground\n");
  for (const auto& t : m.triangles) std::fprintf(f, "f %u %u %u\n", t[0] + 1, t[1] + 1, t[2] + 1);
  if (std::fclose(f) != 0) throw std::runtime_error(path + ": cannot write");
}

/// A scene file around the mesh: one source and a listener above the terrain, diffraction on.
void writeScene(const std::string& path, const std::string& obj) {
  std::ofstream f(path);
  f << R"({"mesh": ")" << obj << R"(",
 "materials": {"ground": {"absorption": [0.1, 0.1, 0.1, 0.1, 0.1, 0.1, 0.1, 0.1],
                          "scattering": 0.3}},
 "sources": [{"name": "s", "position": [1, 3, 1]}],
 "listener": {"position": [2, 3, 2], "radius": 0.5},
 "propagation": {"diffraction": true}})";
  if (!f) throw std::runtime_error(path + ": cannot write");
}

/// The load stages of one terrain size.
Json timeLoad(int cells, int panels, int crates) {
  const test::TempDir dir("dpc_bench_load");
  const std::string obj = (dir.path() / "terrain.obj").string();
  const std::string json = (dir.path() / "terrain.json").string();
  writeObj(test::terrain(uint32_t(cells), uint32_t(panels), uint32_t(crates)), obj);
  writeScene(json, obj);
  Json j;
  auto t = Clock::now();
  const SceneDesc scene = loadScene(json);
  j["triangles"] = scene.mesh.triangles.size();
  j["load_scene_ms"] = msSince(t);
  t = Clock::now();
  const Geometry geometry(scene.mesh, scene.materials, scene.propagation.patchSize, scene.objects);
  j["geometry_ms"] = msSince(t);
  t = Clock::now();
  const EmbreeTracer tracer(scene.mesh, scene.objects);
  j["embree_ms"] = msSince(t);
  t = Clock::now();
  const EdgeDiffraction diffraction(scene.mesh, scene.objects);
  j["edge_finding_ms"] = msSince(t);
  j["edges"] = diffraction.edges().size();
  j["total_ms"] = j["load_scene_ms"].get<double>() + j["geometry_ms"].get<double>() +
                  j["embree_ms"].get<double>() + j["edge_finding_ms"].get<double>();
  return j;
}

}  // namespace

int benchLoad(const LoadOptions& o) {
  Json j;
  j["benchmark"] = "load";
  j["panels"] = o.panels;
  j["crates"] = o.crates;
  j["sizes"] = Json::array();
  for (const int cells : o.cells) {
    const Json s = timeLoad(cells, o.panels, o.crates);
    std::fprintf(stderr, "%zu triangles: load %.0f ms (edges %.0f ms, %zu edges)\n",
                 s["triangles"].get<size_t>(), s["total_ms"].get<double>(),
                 s["edge_finding_ms"].get<double>(), s["edges"].get<size_t>());
    j["sizes"].push_back(s);
  }
  printReport(j);
  return 0;
}

}  // namespace dpc::bench
