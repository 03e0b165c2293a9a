#include "api/field_names.h"

#include <cstring>
#include <utility>

namespace dpc::api {

std::string apiFieldName(const std::string& path, const std::vector<Material>& materials) {
  auto starts = [&](const char* p) { return path.rfind(p, 0) == 0; };
  auto numberAt = [&](size_t at) { return std::stoul(path.substr(at)); };
  auto after = [&](char c, size_t from = 0) { return path.substr(path.find(c, from) + 1); };
  if (path == "audio.cluster_angle") return "cluster_angle_degrees";
  if (starts("propagation.") || starts("audio.")) return after('.');
  if (path == "listeners") return "listeners (1 + additional_listener_count)";
  if (starts("listeners[")) {
    const size_t i = numberAt(10);
    std::string member = after('.');
    if (member == "yaw" || member == "pitch" || member == "roll") member += "_degrees";
    if (i == 0) return "listener_" + member;
    return "additional_listeners[" + std::to_string(i - 1) + "]." + member;
  }
  // A source's pattern and rotation live in the parallel array source_directivities.
  if (const size_t d = path.find("].directivity."); starts("sources[") && d != std::string::npos)
    return "source_directivities[" + std::to_string(numberAt(8)) + "]." + path.substr(d + 14);
  if (starts("sources[") && path.find("].rotation") != std::string::npos)
    return "source_directivities[" + std::to_string(numberAt(8)) + "].rotation";
  if (starts("materials.")) {
    const size_t dot = path.find('.', 10);
    const std::string name = path.substr(10, dot - 10), member = path.substr(dot + 1);
    size_t i = 0;
    while (i + 1 < materials.size() && materials[i].name != name) ++i;
    // A material's transmission loss lives in the parallel array material_transmissions.
    if (const std::string loss = "transmission_loss_db"; member.rfind(loss, 0) == 0)
      return "material_transmissions[" + std::to_string(i) + "].loss_db" +
             member.substr(loss.size());
    const std::string m = member.rfind("scattering", 0) == 0 ? "scattering" : member;
    return "materials[" + std::to_string(i) + "]." + m;
  }
  for (const auto& [from, to] : {std::pair{"mesh.vertices[", "mesh.vertices["},
                                 std::pair{"mesh.triangles[", "mesh.indices["}}) {
    if (!starts(from) || path.find("][") == std::string::npos) continue;
    const size_t element = numberAt(std::strlen(from)), k = numberAt(path.find("][") + 2);
    return to + std::to_string(element * 3 + k) + "]";
  }
  return path;
}

Origin apiOrigin(const char* name, const SceneDesc& scene) {
  return Origin{name, [&scene](const std::string& path) {
                       return apiFieldName(path, scene.materials);
                     }};
}

}  // namespace dpc::api
