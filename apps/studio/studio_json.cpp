#include "apps/studio/studio_json.h"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "analysis/energy_response_csv.h"
#include "analysis/expected_band_analysis.h"

namespace dpc::studio {
namespace {

using nlohmann::json;

json vec(const glm::vec3& v) { return json::array({v.x, v.y, v.z}); }

/// A unit quaternion as [x, y, z, w] (the scene file's and three.js's order).
json quat(const glm::quat& q) { return json::array({q.x, q.y, q.z, q.w}); }

json bands(const Bands& b) {
  json a = json::array();
  for (int i = 0; i < kNumBands; ++i) a.push_back(b[i]);
  return a;
}

/// A number, or null when it is not finite (JSON has no NaN).
json number(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

json figuresJson(const StudioFigures& f) {
  return {{"clock", f.live ? "live" : "offline"},
          {"frameMs", number(f.frameMs)},
          {"raysPerFrame", f.raysPerFrame},
          {"raysPerFrameScene", f.raysPerFrameScene},
          {"raysPerSecond", number(f.raysPerSecond)},
          {"cacheEntries", f.cacheEntries},
          {"cacheMb", number(f.cacheMb)},
          {"cacheBudgetMb", number(f.cacheBudgetMb)},
          {"irAgeMs", number(f.irAgeMs)},
          {"latencyMedianMs", number(f.latencyMedianMs)},
          {"latencyP95Ms", number(f.latencyP95Ms)},
          {"loadPercent", f.live ? number(f.loadPercent) : json(nullptr)},
          {"xruns", f.live ? json(f.xruns) : json(nullptr)}};
}

json pathsJson(const std::vector<SpecularPath>& paths) {
  json a = json::array();
  for (const SpecularPath& p : paths) {
    json points = json::array();
    for (uint32_t k = 0; k < p.order && k < p.points.size(); ++k) points.push_back(vec(p.points[k]));
    a.push_back({{"order", p.order}, {"delaySeconds", p.delaySeconds}, {"points", points},
                 {"intensity", bands(p.intensity)}});
  }
  return a;
}

/// A mesh as flat vertices (x, y, z), flat triangles and a material per triangle.
void meshJson(const Mesh& mesh, json& out) {
  json vertices = json::array(), triangles = json::array();
  for (const glm::vec3& v : mesh.vertices) vertices.insert(vertices.end(), {v.x, v.y, v.z});
  for (const auto& t : mesh.triangles) triangles.insert(triangles.end(), {t[0], t[1], t[2]});
  out["vertices"] = std::move(vertices);
  out["triangles"] = std::move(triangles);
  out["materialIndex"] = mesh.materialIndex;
}

json posesJson(const std::vector<Pose>& poses) {
  json a = json::array();
  for (const Pose& p : poses) a.push_back({{"position", vec(p.position)}, {"rotation", quat(p.rotation)}});
  return a;
}

/// One map of a bake ([probe][source][row][parameter] plus STI in the broadband row), flat;
/// null where not finite, where STI has no row and for probes not done.
json bakeValues(const StudioBake& b, const std::vector<float>& params,
                const std::vector<float>& sti) {
  const size_t nParams = b.parameters.size(), sources = b.sources;
  json out = json::array();
  for (size_t p = 0; p < b.probes.size(); ++p)
    for (size_t s = 0; s < sources; ++s)
      for (size_t row = 0; row < size_t(kBakeRows); ++row) {
        const size_t at = ((p * sources + s) * kBakeRows + row) * nParams;
        for (size_t k = 0; k < nParams; ++k)
          out.push_back(b.done[p] ? number(params[at + k]) : json(nullptr));
        const bool broadband = row + 1 == size_t(kBakeRows);
        out.push_back(b.done[p] && broadband ? number(sti[p * sources + s]) : json(nullptr));
      }
  return out;
}

}  // namespace

std::string bakeJson(const StudioBake& b) {
  json probes = json::array(), done = json::array(), bandsOut = json::array();
  for (const glm::vec3& p : b.probes) probes.insert(probes.end(), {p.x, p.y, p.z});
  for (uint8_t d : b.done) done.push_back(d ? 1 : 0);
  for (float f : kBandCentreHz) bandsOut.push_back(f);
  bandsOut.push_back("broadband");
  json names = b.parameters;
  names.push_back("STI");
  return json{{"file", b.file},
              {"probes", probes},
              {"done", done},
              {"sources", b.sources},
              {"bands", bandsOut},
              {"parameters", names},
              {"values", bakeValues(b, b.values, b.sti)},
              {"ci95", bakeValues(b, b.ci95, b.stiCi95)}}
      .dump();
}

std::string sceneJson(const SceneDesc& scene, const std::string& bakeFile) {
  json out = {{"file", scene.path}, {"bake", bakeFile.empty() ? json(nullptr) : json(bakeFile)}};
  json materials = json::array();
  meshJson(scene.mesh, out);
  for (const Material& m : scene.materials)
    materials.push_back({{"name", m.name}, {"absorption", bands(m.absorption)}});
  json objects = json::array();
  for (const ObjectDesc& o : scene.objects) {
    json mesh = {{"name", o.name}};
    meshJson(o.mesh, mesh);
    objects.push_back(std::move(mesh));
  }
  json sources = json::array(), listeners = json::array();
  for (const SourceDesc& s : scene.sources)
    sources.push_back({{"name", s.name}, {"directivity", bands(s.directivity.a)}});
  for (const ListenerDesc& l : scene.listeners)
    listeners.push_back({{"name", l.name}, {"radius", l.radius}});
  json centres = json::array();
  for (float f : kBandCentreHz) centres.push_back(f);
  out.update({{"materials", materials}, {"objects", objects}, {"sources", sources},
              {"listeners", listeners}, {"bandCentresHz", centres}});
  return out.dump();
}

std::string stateJson(const StudioFrame& f) {
  json listeners = json::array(), sources = json::array();
  for (const glm::vec3& p : f.listeners) listeners.push_back(vec(p));
  for (const glm::vec3& p : f.sources) sources.push_back(vec(p));
  json rotations = json::array(), edges = json::array();
  for (const glm::quat& q : f.sourceRotations) rotations.push_back(quat(q));
  for (const auto& [a, b] : f.edges) edges.push_back({a.x, a.y, a.z, b.x, b.y, b.z});
  const json direct = {{"visible", f.direct.visible},
                       {"distance", f.direct.distance},
                       {"delaySeconds", f.direct.delaySeconds},
                       {"intensity", bands(f.direct.intensity)}};
  return json{{"frame", f.frame},
              {"sceneSeconds", f.sceneSeconds},
              {"played", f.played},
              {"source", f.source},
              {"listeners", listeners},
              {"listenerYaw", f.listenerYaw},
              {"sources", sources},
              {"worldSeconds", f.worldSeconds},
              {"objects", posesJson(f.objects)},
              {"sourceRotations", rotations},
              {"direct", direct},
              {"edges", edges},
              {"surfaces", {{"triangles", f.surfaceTriangles}, {"energy", f.surfaceEnergy}}},
              {"paths", pathsJson(f.paths)},
              {"figures", figuresJson(f.figures)},
              {"publishMicros", f.publishMicros}}
      .dump();
}

std::string responseJson(const StudioFrame& f) {
  json perBand = json::array();
  for (int b = 0; b < kNumBands; ++b) {
    json bins = json::array();
    for (const Bands& e : f.energy) bins.push_back(e[b]);
    perBand.push_back(std::move(bins));
  }
  // Where an IR's analysis puts t0 (the direct sound's arrival), for the page's C80 and D50.
  const double onset = onsetSecondsOf(f.direct);
  return json{{"frame", f.frame},
              {"source", f.source},
              {"binSeconds", f.binSeconds},
              {"onsetSeconds", std::isfinite(onset) ? json(onset) : json(nullptr)},
              {"origin", f.fromBake ? "bake" : "traced"},
              {"bands", perBand}}
      .dump();
}

std::string energyCsv(const StudioFrame& f) {
  if (f.energy.empty()) return energyCsvText({});
  SourceEnergy se;
  se.energy = EnergyResponse(double(f.energy.size()) * f.binSeconds, f.binSeconds);
  // Each bin at its centre: the same bin index whatever the rounding of k * binSeconds.
  for (size_t k = 0; k < f.energy.size(); ++k)
    se.energy.add((double(k) + 0.5) * f.binSeconds, f.energy[k]);
  // The direct sound on a row of its own, as --er-out writes it, taken out of the bin that
  // holds it: an analysis of the file (dpc-analyze) then puts t0 at its arrival, as the page
  // does with /api/response's onsetSeconds, and adds it back to the same bin.
  const double k = double(f.direct.delaySeconds) / f.binSeconds;
  if (f.direct.visible && k >= 0.0 && k < double(f.energy.size())) {
    se.direct = f.direct;
    Bands& bin = se.energy.bins()[size_t(k)];
    for (int b = 0; b < kNumBands; ++b) bin[b] = std::max(0.f, bin[b] - f.direct.intensity[b]);
  }
  return energyCsvText({se});
}

}  // namespace dpc::studio
