// Doors and doorways between two rooms for the door tests (door_gap_test, doorway_test):
// the rooms, the doorway in a thin or a thick wall, leaves, and the direct sound (with its
// edge and slit paths) the engine gives at a listener, re the free field.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <cstdio>
#include <initializer_list>
#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>
#include <numbers>
#include <string>

#include "engine/diffraction.h"
#include "engine/embree_tracer.h"
#include "engine/propagation.h"
#include "scene/scene.h"
#include "testing/test_scenes.h"

namespace dpc::door_test {

inline constexpr double kPi = std::numbers::pi;
inline constexpr float kC = 343.f;
inline const glm::vec3 kSource{3.f, 1.2f, 2.5f}, kListener{9.f, 1.2f, 2.5f};
inline constexpr float kDoorZ0 = 2.f, kDoorWidth = 1.f, kDoorHeight = 2.1f;  // doorway in x = 6

enum class Leaf { kNone, kStatic, kObject };

/// A panel, and with `twice` its copy wound the other way (a double-sided face).
inline void addFace(Mesh& mesh, glm::vec3 o, glm::vec3 u, glm::vec3 v, bool twice) {
  test::addPanel(mesh, o, u, v, 0);
  if (twice) test::addPanel(mesh, o, v, u, 0);
}

/// The partition's panels round the doorway in the plane x = x0.
inline void addDoorwayWall(Mesh& mesh, float x0, bool twice = false) {
  const glm::vec3 y{0, 1, 0}, z{0, 0, 1};
  const float top = 3.f - kDoorHeight, right = 5.f - kDoorZ0 - kDoorWidth;
  addFace(mesh, {x0, 0, 0}, kDoorZ0 * z, kDoorHeight * y, twice);
  addFace(mesh, {x0, kDoorHeight, 0}, kDoorZ0 * z, top * y, twice);
  addFace(mesh, {x0, kDoorHeight, kDoorZ0}, kDoorWidth * z, top * y, twice);
  addFace(mesh, {x0, kDoorHeight, kDoorZ0 + kDoorWidth}, right * z, top * y, twice);
  addFace(mesh, {x0, 0, kDoorZ0 + kDoorWidth}, right * z, kDoorHeight * y, twice);
}

/// The same wall meshed with T-junctions: the jamb panels run the wall's full height and the
/// lintel panel sits between them (the jambs' edges run 0.9 m past the doorway's top).
inline void addTeeDoorwayWall(Mesh& mesh, float x0 = 6.f) {
  const glm::vec3 y{0, 1, 0}, z{0, 0, 1};
  const float top = 3.f - kDoorHeight, right = 5.f - kDoorZ0 - kDoorWidth;
  test::addPanel(mesh, {x0, 0, 0}, kDoorZ0 * z, 3.f * y, 0);
  test::addPanel(mesh, {x0, kDoorHeight, kDoorZ0}, kDoorWidth * z, top * y, 0);
  test::addPanel(mesh, {x0, 0, kDoorZ0 + kDoorWidth}, right * z, 3.f * y, 0);
}

/// Two rooms 6 x 3 x 5 m along x, joined by the doorway (z 2..3, y 0..2.1) in the partition
/// x = 6 (double-sided sheets; the jambs end at the lintel), and the leaf: a sheet in the
/// doorway's plane leaving `gap` metres at both sides and the top, standing on the floor; in
/// the static mesh or as a scene object (as scenes/two_rooms.json has it). All opaque, of
/// absorption `alpha`.
inline SceneDesc doorScene(float gap, Leaf leaf, float alpha = 0.2f, bool tee = false) {
  SceneDesc s = test::makeShoebox({12, 3, 5}, Bands(alpha), 0.3f, kSource, kListener, 0.5f);
  const glm::vec3 y{0, 1, 0}, z{0, 0, 1};
  if (tee)
    addTeeDoorwayWall(s.mesh);
  else
    addDoorwayWall(s.mesh, 6.f);
  const glm::vec3 corner{6.f, 0.f, kDoorZ0 + gap};
  const glm::vec3 along = (kDoorWidth - 2.f * gap) * z, up = (kDoorHeight - gap) * y;
  if (leaf == Leaf::kStatic) test::addPanel(s.mesh, corner, along, up, 0);
  if (leaf == Leaf::kObject) {
    ObjectDesc door;
    door.name = "leaf";
    test::addPanel(door.mesh, {0, 0, 0}, along, up, 0);
    door.trajectory = {ObjectKeyframe{0.0, corner, glm::quat(1, 0, 0, 0)}};
    s.objects.push_back(door);
  }
  s.propagation.raysPerFrame = 8192;
  s.propagation.maxOrder = 40;
  s.propagation.exactOrder = 0;
  s.propagation.irLength = 1.f;
  return s;
}

/// doorScene's rooms with the doorway through a wall `depth` metres deep: its faces x = 6 and
/// 6 + depth and the doorway's reveals (two jambs and the lintel), every face once or
/// (doubleSided) twice, as an exporter writes a two-sided material; with `tee` each face
/// written with T-junctions (addTeeDoorwayWall: the jambs' reveals meet the face's strips
/// along their sides without sharing the corners at the lintel's height).
inline SceneDesc thickDoorwayScene(float depth, bool doubleSided, float alpha = 0.2f,
                                   bool tee = false) {
  SceneDesc s = doorScene(0.f, Leaf::kNone, alpha);
  s.mesh = test::makeShoebox({12, 3, 5}, Bands(alpha), 0.3f, kSource, kListener, 0.5f).mesh;
  const glm::vec3 x{depth, 0, 0}, y{0, 1, 0}, z{0, 0, 1};
  for (const float x0 : {6.f, 6.f + depth}) {
    if (tee)
      addTeeDoorwayWall(s.mesh, x0);
    else
      addDoorwayWall(s.mesh, x0, doubleSided);
  }
  addFace(s.mesh, {6, 0, kDoorZ0}, x, kDoorHeight * y, doubleSided);
  addFace(s.mesh, {6, 0, kDoorZ0 + kDoorWidth}, kDoorHeight * y, x, doubleSided);
  addFace(s.mesh, {6, kDoorHeight, kDoorZ0}, kDoorWidth * z, x, doubleSided);
  return s;
}

/// A wall standing alone, 60 x 62 m and `depth` thick (x from -depth/2 to depth/2, no floor: the
/// sill is its reveal), with a doorway 0.9 x 2.1 m (z -0.45..0.45, y 0..2.1): one closed solid,
/// single-sided faces, their normals out into the air if `outward`, else into the wall (as the
/// held-out sweep's generator wrote them).
inline void addFreeWallDoorway(Mesh& mesh, float depth, bool outward) {
  const float x0 = -0.5f * depth, x1 = 0.5f * depth, dz = 0.45f, dh = 2.1f;
  const auto quad = [&](glm::vec3 a, glm::vec3 b, glm::vec3 d) {
    if (outward) std::swap(b, d);
    const auto base = uint32_t(mesh.vertices.size());
    mesh.vertices.insert(mesh.vertices.end(), {a, b, b + d - a, d});
    for (const std::array<uint32_t, 3>& t : {std::array<uint32_t, 3>{0, 1, 2}, {0, 2, 3}}) {
      mesh.triangles.push_back({base + t[0], base + t[1], base + t[2]});
      mesh.materialIndex.push_back(0);
    }
  };
  const float zs[] = {-30.f, -dz, dz, 30.f}, ys[] = {-30.f, 0.f, dh, 32.f};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      if (i == 1 && j == 1) continue;
      const float za = zs[i], zb = zs[i + 1], ya = ys[j], yb = ys[j + 1];
      quad({x0, ya, za}, {x0, yb, za}, {x0, ya, zb});
      quad({x1, ya, za}, {x1, ya, zb}, {x1, yb, za});
    }
  for (int i = 0; i < 3; ++i) {  // the wall's rims
    quad({x0, 32.f, zs[i]}, {x0, 32.f, zs[i + 1]}, {x1, 32.f, zs[i]});
    quad({x0, -30.f, zs[i]}, {x1, -30.f, zs[i]}, {x0, -30.f, zs[i + 1]});
    quad({x0, ys[i], -30.f}, {x1, ys[i], -30.f}, {x0, ys[i + 1], -30.f});
    quad({x0, ys[i], 30.f}, {x0, ys[i + 1], 30.f}, {x1, ys[i], 30.f});
  }
  quad({x0, 0.f, -dz}, {x1, 0.f, -dz}, {x0, dh, -dz});  // the reveals
  quad({x0, 0.f, dz}, {x0, dh, dz}, {x1, 0.f, dz});
  quad({x0, dh, -dz}, {x1, dh, -dz}, {x0, dh, dz});
  quad({x0, 0.f, -dz}, {x0, 0.f, dz}, {x1, 0.f, -dz});
}


/// thickDoorwayScene(depth)'s doorway closed by a leaf standing on the floor `gap` metres from
/// the jambs and the lintel: a sheet in the plane x (thickness 0) or a solid box `thickness`
/// metres deep centred on it (a real door's leaf, set in its frame). All of absorption alpha.
inline SceneDesc recessedLeafScene(float depth, float gap, float thickness, float x,
                                   float alpha = 0.2f) {
  SceneDesc s = thickDoorwayScene(depth, false, alpha);
  const glm::vec3 y{0, 1, 0}, z{0, 0, 1};
  if (thickness > 0.f)
    test::addSolidBox(s.mesh, {x - 0.5f * thickness, 0.f, kDoorZ0 + gap},
                      {x + 0.5f * thickness, kDoorHeight - gap, kDoorZ0 + kDoorWidth - gap}, 0);
  else
    test::addPanel(s.mesh, {x, 0.f, kDoorZ0 + gap}, (kDoorWidth - 2.f * gap) * z,
                   (kDoorHeight - gap) * y, 0);
  return s;
}

/// A door stop for a leaf `thickness` deep from x0 to x0 + thickness (stoppedLeafScene) into the
/// mesh: strips `lip` wide round the jambs and the lintel, 2 cm deep, `gap` behind the leaf
/// (side > 0) or before it (side < 0).
inline void addDoorStop(Mesh& mesh, float gap, float thickness, float x0, float side, float lip) {
  constexpr float kStopDepth = 0.02f;
  const float a = side > 0.f ? x0 + thickness + gap : x0 - gap - kStopDepth, b = a + kStopDepth;
  const float z0 = kDoorZ0, z1 = kDoorZ0 + kDoorWidth, h = kDoorHeight;
  test::addSolidBox(mesh, {a, 0.f, z0}, {b, h, z0 + lip}, 0);
  test::addSolidBox(mesh, {a, 0.f, z1 - lip}, {b, h, z1}, 0);
  test::addSolidBox(mesh, {a, h - lip, z0 + lip}, {b, h, z1 - lip}, 0);
}

/// recessedLeafScene's box leaf (`thickness` deep, from x0 to x0 + thickness) closed against a
/// door stop: a strip `lip` metres wide round the jambs and the lintel, 2 cm deep, `gap` metres
/// behind the leaf (side > 0) or before it (side < 0), so each gap turns between the leaf's
/// face and the stop (an L-shaped gap, the stop overlapping the leaf by lip - gap).
inline SceneDesc stoppedLeafScene(float depth, float gap, float thickness, float x0, float side,
                                  float lip) {
  SceneDesc s = recessedLeafScene(depth, gap, thickness, x0 + 0.5f * thickness);
  addDoorStop(s.mesh, gap, thickness, x0, side, lip);
  return s;
}

/// recessedLeafScene's box leaf as a scene object (a game's door, moved by its trajectory; its
/// own edges have no first-order paths), at rest closed.
inline SceneDesc objectLeafScene(float depth, float gap, float thickness, float x) {
  SceneDesc s = thickDoorwayScene(depth, false);
  ObjectDesc door;
  door.name = "leaf";
  test::addSolidBox(door.mesh, {-0.5f * thickness, 0.f, 0.f},
                    {0.5f * thickness, kDoorHeight - gap, kDoorWidth - 2.f * gap}, 0);
  door.trajectory = {ObjectKeyframe{0.0, glm::vec3(x, 0.f, kDoorZ0 + gap), glm::quat(1, 0, 0, 0)}};
  s.objects.push_back(door);
  return s;
}

/// The scene with its moving objects written into the static mesh at their first keyframe's
/// pose: the same leaf as a static one.
inline SceneDesc objectsInMesh(SceneDesc s) {
  for (const ObjectDesc& d : s.objects) {
    const glm::quat r = d.trajectory.empty() ? glm::quat(1, 0, 0, 0) : d.trajectory[0].rotation;
    const glm::vec3 t = d.trajectory.empty() ? glm::vec3(0.f) : d.trajectory[0].position;
    const auto base = uint32_t(s.mesh.vertices.size());
    for (const glm::vec3& v : d.mesh.vertices) s.mesh.vertices.push_back(r * v + t);
    for (auto tri : d.mesh.triangles) {
      for (uint32_t& i : tri) i += base;
      s.mesh.triangles.push_back(tri);
    }
    s.mesh.materialIndex.insert(s.mesh.materialIndex.end(), d.mesh.materialIndex.begin(),
                                d.mesh.materialIndex.end());
  }
  s.objects.clear();
  return s;
}

/// thickDoorwayScene(depth)'s doorway closed by two box leaves `thickness` deep centred on the
/// plane x, meeting in its middle `middle` metres apart, `gap` from the jambs and the lintel,
/// standing on the floor.
inline SceneDesc doubleBoxDoorScene(float depth, float gap, float middle, float thickness,
                                    float x) {
  SceneDesc s = thickDoorwayScene(depth, false);
  const float half = 0.5f * (kDoorWidth - middle) - gap, top = kDoorHeight - gap;
  const float x0 = x - 0.5f * thickness, x1 = x + 0.5f * thickness;
  test::addSolidBox(s.mesh, {x0, 0.f, kDoorZ0 + gap}, {x1, top, kDoorZ0 + gap + half}, 0);
  test::addSolidBox(s.mesh, {x0, 0.f, kDoorZ0 + kDoorWidth - gap - half},
                    {x1, top, kDoorZ0 + kDoorWidth - gap}, 0);
  return s;
}

/// doorScene's doorway closed by two leaves (in the mesh) meeting in its middle, `middle`
/// metres apart there (on the line of sight), `gap` from the frame at the sides and the top.
inline SceneDesc doubleDoorScene(float gap, float middle) {
  SceneDesc s = doorScene(0.f, Leaf::kNone);
  const glm::vec3 y{0, 1, 0}, z{0, 0, 1};
  const float half = 0.5f * (kDoorWidth - middle) - gap, up = kDoorHeight - gap;
  test::addPanel(s.mesh, {6.f, 0.f, kDoorZ0 + gap}, half * z, up * y, 0);
  test::addPanel(s.mesh, {6.f, 0.f, kDoorZ0 + 0.5f * (kDoorWidth + middle)}, half * z, up * y, 0);
  return s;
}

/// The direct sound (with edge diffraction) at `listener` from `source`, band intensity
/// relative to the free field at the same distance; air ignored.
inline Bands directLevel(const SceneDesc& scene, glm::vec3 source = kSource,
                         glm::vec3 listener = kListener) {
  EmbreeTracer tracer(scene.mesh, scene.objects);
  const EdgeDiffraction diffraction(scene.mesh, scene.objects);
  const glm::vec3 v = listener - source;
  const float dist = glm::length(v);
  DirectSound d;
  d.visible = !tracer.occluded(TraceRay{source, v / dist, 1e-3f, dist - 1e-3f});
  d.distance = dist;
  d.delaySeconds = dist / kC;
  d.direction = -v / dist;
  d.intensity = d.visible ? Bands(float(1.0 / (4 * kPi * dist * dist))) : Bands(0.f);
  diffraction.apply(tracer, source, ListenerSphere{listener, 0.5f}, kC, Bands(0.f), d);
  return d.intensity * float(4 * kPi * dist * dist);
}

/// Prints `label`, then per band from 63 Hz to band `last` the levels of each row (dB) joined
/// by '/', and a newline: a door test's table, one line per case.
inline void printLevels(const char* label, std::initializer_list<const Bands*> rows,
                        int last = kNumBands - 1) {
  std::printf("%s", label);
  for (int b = 0; b <= last; ++b) {
    const char* sep = " ";
    for (const Bands* r : rows) {
      std::printf("%s%5.1f", sep, double((*r)[b]));
      sep = "/";
    }
  }
  std::printf("\n");
}

/// The object leaf `scene` (objectLeafScene) turned `degrees` about its hinge, away from a door
/// stop on `side` (> 0: behind the leaf, turned toward the source; < 0 the other way).
inline SceneDesc swungAwayFromStop(SceneDesc scene, float side, float degrees) {
  const float swing = glm::radians(degrees) * (side > 0.f ? -1.f : 1.f);
  scene.objects[0].trajectory[0].rotation = glm::angleAxis(swing, glm::vec3(0, 1, 0));
  return scene;
}

/// Gauss-Legendre, 8 points on [-1, 1].
inline constexpr std::array<double, 8> kGlX = {
    -0.9602898564975363, -0.7966664774136267, -0.5255324099163290, -0.1834346424956498,
    0.1834346424956498,  0.5255324099163290,  0.7966664774136267,  0.9602898564975363};
inline constexpr std::array<double, 8> kGlW = {
    0.1012285362903763, 0.2223810344533745, 0.3137066458778873, 0.3626837833783620,
    0.3626837833783620, 0.3137066458778873, 0.2223810344533745, 0.1012285362903763};

inline Bands decibels(const Bands& x) {
  Bands out;
  for (int b = 0; b < kNumBands; ++b)
    out[b] = float(10 * std::log10(std::max(double(x[b]), 1e-30)));
  return out;
}

/// scenes/two_rooms.json with its door held at its first keyframe, the talker's position,
/// listener b's, and the open doorway's direct level between them (the door taken out, dB).
struct TwoRoomsDoor {
  SceneDesc scene;
  glm::vec3 talker{0.f}, b{0.f};
  Bands open{0.f};
};

inline TwoRoomsDoor twoRoomsDoor() {
  TwoRoomsDoor d;
  d.scene = loadScene(std::string(DPC_SOURCE_DIR) + "/scenes/two_rooms.json");
  d.scene.objects[0].trajectory.resize(1);
  d.talker = d.scene.sources[0].trajectory[0].position;
  d.b = d.scene.listeners[1].position;
  SceneDesc doorway = d.scene;
  doorway.objects.clear();
  d.open = decibels(directLevel(doorway, d.talker, d.b));
  return d;
}

/// Turns `scene`'s first object (a door hinged on its frame's y axis) to `degrees`.
inline void turnDoor(SceneDesc& scene, float degrees) {
  scene.objects[0].trajectory[0].rotation =
      glm::angleAxis(glm::radians(degrees), glm::vec3(0, 1, 0));
}

}  // namespace dpc::door_test
