// Scenes built in code for engine tests (no files needed).
#pragma once

#include <glm/vec3.hpp>

#include "engine/scene.h"

namespace dpc::test {

/// Closed box [0,size.x] x [0,size.y] x [0,size.z] metres, 12 triangles facing inward, one
/// material. Source at `source`, static listener at `listener`.
inline SceneDesc makeShoebox(glm::vec3 size, Bands absorption, float scattering, glm::vec3 source,
                             glm::vec3 listener, float radius = 0.5f) {
  SceneDesc s;
  s.path = "<test shoebox>";
  s.materials.push_back(Material{"walls", absorption, scattering});
  auto& v = s.mesh.vertices;
  for (int i = 0; i < 8; ++i)
    v.push_back({(i & 1) ? size.x : 0.f, (i & 2) ? size.y : 0.f, (i & 4) ? size.z : 0.f});
  // Quads (a, b, c, d) in counter-clockwise order seen from inside.
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    s.mesh.triangles.push_back({uint32_t(q[0]), uint32_t(q[1]), uint32_t(q[2])});
    s.mesh.triangles.push_back({uint32_t(q[0]), uint32_t(q[2]), uint32_t(q[3])});
  }
  s.mesh.materialIndex.assign(s.mesh.triangles.size(), 0);
  s.sources.push_back(SourceDesc{"source", source, "", 0.f});
  s.listener.position = listener;
  s.listener.radius = radius;
  return s;
}

/// Eyring's reverberation time of a box, seconds: T = 0.161 V / (-S ln(1 - alpha) + 4 m V)
/// (Kuttruff, Room Acoustics, eq. 5.24 with air attenuation m in 1/m; 0.161 = 24 ln10 / c at
/// c = 343 m/s: we use 24 ln10 / c exactly).
inline double eyringT60(glm::vec3 size, double alpha, double c, double airM = 0.0) {
  const double V = double(size.x) * size.y * size.z;
  const double S =
      2.0 * (double(size.x) * size.y + double(size.y) * size.z + double(size.z) * size.x);
  return 24.0 * std::log(10.0) / c * V / (-S * std::log(1.0 - alpha) + 4.0 * airM * V);
}

}  // namespace dpc::test
