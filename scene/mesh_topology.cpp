#include "scene/mesh_topology.h"

#include <cstring>
#include <glm/vec3.hpp>
#include <unordered_map>

namespace dpc {

std::vector<uint32_t> weldedVertexIds(const Mesh& mesh) {
  struct Key {
    uint32_t x, y, z;
    bool operator==(const Key&) const = default;
  };
  struct Hash {
    size_t operator()(const Key& k) const {
      return size_t(k.x) * 0x9e3779b97f4a7c15ULL ^ size_t(k.y) * 0xc2b2ae3d27d4eb4fULL ^
             size_t(k.z) * 0x165667b19e3779f9ULL;
    }
  };
  auto bits = [](float f) {
    f += 0.f;  // -0 and +0 are one position
    uint32_t u;
    std::memcpy(&u, &f, sizeof u);
    return u;
  };
  std::unordered_map<Key, uint32_t, Hash> first;
  first.reserve(mesh.vertices.size());
  std::vector<uint32_t> ids(mesh.vertices.size());
  for (uint32_t i = 0; i < mesh.vertices.size(); ++i) {
    const glm::vec3& v = mesh.vertices[i];
    ids[i] = first.try_emplace(Key{bits(v.x), bits(v.y), bits(v.z)}, i).first->second;
  }
  return ids;
}

}  // namespace dpc
