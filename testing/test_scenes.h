// Scenes built in code for engine tests (no files needed).
#pragma once

#include <array>
#include <cmath>
#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>
#include <initializer_list>
#include <memory>
#include <string>

#include "scene/scene.h"

namespace dpc::test {

/// A shared read-only copy of v: the runtime's stages and sessions share their scene and dry
/// signals (std::shared_ptr<const T>).
template <class T>
std::shared_ptr<const T> shared(const T& v) {
  return std::make_shared<const T>(v);
}

/// Closed box [0,size.x] x [0,size.y] x [0,size.z] metres, 12 triangles facing inward, one
/// material. Source at `source`, static listener at `listener`.
inline SceneDesc makeShoebox(glm::vec3 size, Bands absorption, float scattering, glm::vec3 source,
                             glm::vec3 listener, float radius = 0.5f) {
  SceneDesc s;
  s.path = "<test shoebox>";
  s.materials.push_back(Material{"walls", absorption, Bands(scattering)});
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
  SourceDesc src;
  src.name = "source";
  src.position = source;
  s.sources.push_back(src);
  ListenerDesc l;
  l.position = listener;
  l.radius = radius;
  s.listeners.push_back(l);
  return s;
}

/// A 12 x 4 x 9 m room (absorption 0.15, scattering 0.6), one listener, `count` sources on a
/// ring around it at 2 .. 4.5 m in stereo.
inline SceneDesc ringScene(int count) {
  SceneDesc s = test::makeShoebox({12, 4, 9}, Bands(0.15f), 0.6f, {3, 1.5f, 3}, {6, 1.6f, 4.5f});
  s.audio.output = OutputFormat::kStereo;
  s.audio.blockSize = 256;
  s.propagation.irLength = 1.2f;
  s.propagation.raysPerFrame = 3000;
  s.sources.clear();
  for (int i = 0; i < count; ++i) {
    const float a = 2.f * float(M_PI) * float(i) / float(count), r = 2.f + 0.25f * float(i % 11);
    SourceDesc d;
    d.name = "s" + std::to_string(i);
    d.position = {6.f + r * std::cos(a), 1.2f + 0.1f * float(i % 5), 4.5f + r * std::sin(a)};
    s.sources.push_back(d);
  }
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

/// Appends a double-sided rectangular panel (4 triangles) of material m: corner o, edges u, v.
inline void addPanel(Mesh& mesh, glm::vec3 o, glm::vec3 u, glm::vec3 v, uint32_t m) {
  const auto base = uint32_t(mesh.vertices.size());
  mesh.vertices.insert(mesh.vertices.end(), {o, o + u, o + u + v, o + v});
  for (const std::array<uint32_t, 3>& t :
       std::initializer_list<std::array<uint32_t, 3>>{{0, 1, 2}, {0, 2, 3}, {0, 2, 1}, {0, 3, 2}}) {
    mesh.triangles.push_back({base + t[0], base + t[1], base + t[2]});
    mesh.materialIndex.push_back(m);
  }
}

/// Appends a solid box [lo, hi] (8 corners of its own, 12 triangles, normals out into the air,
/// material m): its edges are 90-degree wedges, one closed body.
inline void addSolidBox(Mesh& mesh, glm::vec3 lo, glm::vec3 hi, uint32_t m) {
  const auto base = uint32_t(mesh.vertices.size());
  for (int i = 0; i < 8; ++i)
    mesh.vertices.push_back({(i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z});
  const int quads[6][4] = {{0, 1, 3, 2}, {4, 6, 7, 5}, {0, 4, 5, 1},
                           {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 5, 7, 3}};
  for (const auto& q : quads) {  // each quad wound inward as listed: written the other way
    mesh.triangles.push_back({base + uint32_t(q[0]), base + uint32_t(q[2]), base + uint32_t(q[1])});
    mesh.triangles.push_back({base + uint32_t(q[0]), base + uint32_t(q[3]), base + uint32_t(q[2])});
    mesh.materialIndex.insert(mesh.materialIndex.end(), {m, m});
  }
}

/// Appends `part`'s vertices and triangles (materials as they are) after mesh's own.
inline void appendMesh(Mesh& mesh, const Mesh& part) {
  const auto base = uint32_t(mesh.vertices.size());
  mesh.vertices.insert(mesh.vertices.end(), part.vertices.begin(), part.vertices.end());
  for (const std::array<uint32_t, 3>& t : part.triangles)
    mesh.triangles.push_back({base + t[0], base + t[1], base + t[2]});
  mesh.materialIndex.insert(mesh.materialIndex.end(), part.materialIndex.begin(),
                            part.materialIndex.end());
}

/// A solid cube [0, size]^3 (addSolidBox, material 0).
inline Mesh solidBox(float size) {
  Mesh m;
  addSolidBox(m, glm::vec3(0.f), glm::vec3(size), 0);
  return m;
}

/// A 4.1 x 2.7 x 3.3 m box (absorption 0.08) with a partition of another material (0.4) at
/// x = 1.7 m from the floor to 1.6 m, z in [0, 1.9] m, the wave band on up to 250 Hz: a room
/// with no symmetry to hide an error of the wave solver. Source (0.7, 1.1, 0.9) m, listener
/// (3.2, 1.9, 2.6) m.
inline SceneDesc partitionedWaveBox() {
  SceneDesc s = makeShoebox({4.1f, 2.7f, 3.3f}, Bands(0.08f), 0.1f, {0.7f, 1.1f, 0.9f},
                            {3.2f, 1.9f, 2.6f});
  s.materials.push_back(Material{"panel", Bands(0.4f), Bands(0.1f)});
  addPanel(s.mesh, {1.7f, 0.f, 0.f}, {0.f, 1.6f, 0.f}, {0.f, 0.f, 1.9f}, 1);
  s.wave.enabled = true;
  s.wave.maxFrequencyHz = 250.f;
  return s;
}

/// Two rooms 5 x 3 x 4 m side by side along x (x in [0, 10]), joined by a 1 m wide, 2 m high
/// doorway in the wall x = 5 at z in [3, 4]; a door panel (local frame: the doorway's size
/// plus 5 cm all round, 1 cm off the wall) seals it when placed at the doorway. Source and
/// listener sit in different rooms without line of sight.
inline SceneDesc twoRooms(DpcWeighting weighting, float tau) {
  SceneDesc s = test::makeShoebox({10, 3, 4}, Bands(0.1f), 0.6f, {2, 1.2f, 1}, {8, 1.2f, 1}, 0.5f);
  const glm::vec3 y{0, 1, 0}, z{0, 0, 1};
  addPanel(s.mesh, {5, 0, 0}, 3.f * z, 3.f * y, 0);  // below z = 3, full height
  addPanel(s.mesh, {5, 2, 3}, 1.f * z, 1.f * y, 0);  // above the doorway
  ObjectDesc door;
  door.name = "door";
  addPanel(door.mesh, {0, -0.05f, -0.05f}, 1.1f * z, 2.1f * y, 0);
  ObjectKeyframe shut;
  shut.position = {5.01f, 0.f, 3.f};
  door.trajectory = {shut};
  s.objects.push_back(door);
  s.propagation.estimator = Estimator::kDpc;
  s.propagation.dpcWeighting = weighting;
  s.propagation.cacheTau = tau;
  s.propagation.frameRate = 10.f;
  s.propagation.raysPerFrame = 8192;
  s.propagation.maxOrder = 40;
  return s;
}

inline const Pose kDoorShut{{5.01f, 0.f, 3.f}, glm::quat(1, 0, 0, 0)};
/// Swung open by 90 degrees about its hinge edge (the vertical edge at z = 3): into room B.
inline const Pose kDoorOpen{{5.01f, 0.f, 2.95f},
                            glm::angleAxis(float(3.14159265358979323846 / 2), glm::vec3(0, 1, 0))};

}  // namespace dpc::test
