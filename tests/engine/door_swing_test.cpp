// A door swung open a little at a time, as a game opens one: a 4 cm box leaf in a 0.2 m wall's
// doorway, hinged at its corner, turned 0-30 degrees toward the source, as a moving object and
// written into the static mesh. Ajar, it passes three openings: the gap at its hinge, the
// opening between its latch rim and the jamb's corner once the rim has left the reveal (1 to
// 25 cm apart, at a slant), and the slot under the lintel where the leaf stands out of the
// wall. Below their first cross modes they pass what slits pass (engine/slit.h: Gomperts 1964;
// Mechel 1986), here computed on their own by tests/engine/slit_model.h from the leaf's
// geometry. Before engine/openings.h, the path round the latch rim was a free edge or a chain
// at a screen's level wherever the gap probe missed the slanted opening: 4-20 degrees read
// the open doorway's level at 63 Hz, up to 6 dB above the slit model, and the level stepped
// by 5-11 dB between neighbouring degrees.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>
#include <vector>

#include "engine/diffraction.h"
#include "engine/simulation.h"
#include "testing/test_scenes.h"
#include "tests/engine/door_scenes.h"
#include "tests/engine/slit_model.h"

using namespace dpc;
using namespace dpc::door_test;

namespace {

constexpr double kThickness = 0.04, kGap = 0.005, kFront = 6.01;  // m; the leaf's front face
constexpr double kLeafWidth = kDoorWidth - 2 * kGap, kLeafHeight = kDoorHeight - kGap;

/// thickDoorwayScene(0.2)'s doorway with the leaf as a moving object, `degrees` about its
/// front hinge corner (x 6.01, z 2.005) toward the source.
SceneDesc swungLeaf(double degrees) {
  SceneDesc s = thickDoorwayScene(0.2f, false);
  ObjectDesc door;
  door.name = "leaf";
  test::addSolidBox(door.mesh, {0.f, 0.f, 0.f},
                    {float(kThickness), float(kLeafHeight), float(kLeafWidth)}, 0);
  const glm::quat turn = glm::angleAxis(-float(glm::radians(degrees)), glm::vec3(0, 1, 0));
  door.trajectory = {ObjectKeyframe{
      0.0, glm::vec3(float(kFront), 0.f, float(kDoorZ0 + kGap)), turn}};
  s.objects.push_back(door);
  return s;
}

/// The leaf's point (x across its thickness from its front face, z along its width from the
/// hinge) in the room, turned `degrees` (y dropped).
glm::dvec3 leafPoint(double x, double z, double degrees) {
  const double a = glm::radians(degrees);
  return {kFront + x * std::cos(a) - z * std::sin(a), 0.0,
          kDoorZ0 + kGap + x * std::sin(a) + z * std::cos(a)};
}

/// The slits of the leaf ajar: its latch gap (5 mm, as deep as the leaf, while the back rim is
/// in the reveal; then the opening from the rim to the jamb's front corner, without depth);
/// its hinge gap (widening as the back hinge corner turns off the jamb); the slot under the
/// lintel in 20 pieces, each the 5 mm gap as deep as the leaf where the leaf is in the reveal
/// and the opening from its top back edge to the lintel's front corner where it stands out.
std::vector<Slit> openings(double degrees) {
  std::vector<Slit> out;
  const glm::dvec3 rim = leafPoint(kThickness, kLeafWidth, degrees);
  const glm::dvec3 jamb(6.0, 0.0, kDoorZ0 + kDoorWidth);
  const double mid = kFront + 0.5 * kThickness;
  if (rim.x < 6.0) {
    const glm::dvec3 c = 0.5 * (rim + jamb);
    out.push_back({{c.x, 0, c.z}, {c.x, kLeafHeight, c.z}, glm::length(rim - jamb), 0.0});
  } else {
    const double w = jamb.z - rim.z;
    out.push_back({{mid, 0, rim.z + w / 2}, {mid, kLeafHeight, rim.z + w / 2}, w, kThickness});
  }
  const double hinge = leafPoint(kThickness, 0.0, degrees).z - kDoorZ0;
  out.push_back({{mid, 0, kDoorZ0 + hinge / 2}, {mid, kLeafHeight, kDoorZ0 + hinge / 2}, hinge,
                 kThickness});
  constexpr int kPieces = 20;
  for (int i = 0; i < kPieces; ++i) {
    const double z0 = kLeafWidth * i / kPieces, z1 = kLeafWidth * (i + 1) / kPieces;
    const glm::dvec3 p0 = leafPoint(kThickness, z0, degrees);
    const glm::dvec3 p1 = leafPoint(kThickness, z1, degrees);
    const double out_of_wall = 6.0 - 0.5 * (p0.x + p1.x);
    if (out_of_wall <= 0.0) {
      const glm::dvec3 c0 = leafPoint(kThickness / 2, z0, degrees);
      const glm::dvec3 c1 = leafPoint(kThickness / 2, z1, degrees);
      const double y = kDoorHeight - kGap / 2;
      out.push_back({{c0.x, y, c0.z}, {c1.x, y, c1.z}, kGap, kThickness});
    } else {
      const double w = std::hypot(out_of_wall, kGap), y = kDoorHeight - 0.5 * w;
      out.push_back({{6.0, y, p0.z}, {6.0, y, p1.z}, w, 0.0});
    }
  }
  return out;
}

}  // namespace

TEST_CASE(
    "Door swing: a box leaf ajar 2-15 degrees passes what the slit model of its openings "
    "says",
    "[diffraction][door][heavy]") {
  // Up to 15 degrees the latch opening (up to 26 cm) is at least 8 times as long as wide, where
  // the slit model holds fully (engine/slit.h kSlitFullAspect). Tolerance: 3 dB per octave at
  // 63-250 Hz, as for the gaps round a closed leaf (door_gap_test); the model here places the
  // slanted openings in the wall's plane. Found -1.7 to +2.0 dB. The object and the same leaf
  // in the static mesh within 1 dB from 63 Hz to 1 kHz (found 0.1 at most; before, the object's
  // rim without a probed gap stayed a chain: 1.7 dB apart at 18 degrees).
  const MouthImpedance zr;
  for (double degrees = 2.0; degrees <= 15.0; degrees += 1.0) {
    const SceneDesc scene = swungLeaf(degrees);
    const Bands object = decibels(directLevel(scene));
    const Bands mesh = decibels(directLevel(objectsInMesh(scene)));
    const Bands model = modelLevels(openings(degrees), zr);
    char label[96];
    std::snprintf(label, sizeof label, "leaf ajar %4.1f deg: object / in the mesh / model (dB)",
                  degrees);
    printLevels(label, {&object, &mesh, &model}, 4);
    for (int b = 0; b <= 4; ++b) {
      INFO(degrees << " degrees, band " << b);
      if (b <= 2) CHECK(std::abs(object[b] - model[b]) < 3.f);
      CHECK(std::abs(object[b] - mesh[b]) < 1.f);
    }
  }
}

TEST_CASE("Door swing: swung open half a degree at a time, the leaf never steps nor dips below "
          "shut", "[diffraction][door][heavy]") {
  // 0-30 degrees by half degrees, 63 and 125 Hz. Opening only widens the gaps, so the level
  // never falls below shut (1 dB: the hinge gap's probe resolves a width to 5 %, 0.4 dB). No
  // half degree changes the level by more than 3 dB, or than the slit model's own change where
  // that is larger (up to 5 dB, as the latch rim leaves the reveal at 2.5-3 degrees; the model
  // is computed to 15 degrees, where it holds). Without a step in the door, 3 dB is a step in
  // the engine (before: 5-11 dB between neighbouring degrees).
  const MouthImpedance zr;
  const Bands shutObject = decibels(directLevel(swungLeaf(0.0)));
  const Bands shutMesh = decibels(directLevel(objectsInMesh(swungLeaf(0.0))));
  Bands lastObject = shutObject, lastMesh = shutMesh, lastModel = modelLevels(openings(0.0), zr);
  float largest = 0.f;
  for (double degrees = 0.5; degrees <= 30.0; degrees += 0.5) {
    const SceneDesc scene = swungLeaf(degrees);
    const Bands object = decibels(directLevel(scene));
    const Bands mesh = decibels(directLevel(objectsInMesh(scene)));
    const Bands model = degrees <= 15.0 ? modelLevels(openings(degrees), zr) : lastModel;
    for (int b = 0; b <= 1; ++b) {
      INFO(degrees << " degrees, band " << b);
      CHECK(object[b] > shutObject[b] - 1.f);
      CHECK(mesh[b] > shutMesh[b] - 1.f);
      const float allowed = std::max(3.f, std::abs(model[b] - lastModel[b]));
      for (float step : {object[b] - lastObject[b], mesh[b] - lastMesh[b]}) {
        largest = std::max(largest, std::abs(step));
        CHECK(std::abs(step) <= allowed);
      }
    }
    lastObject = object;
    lastMesh = mesh;
    lastModel = model;
  }
  std::printf("63-125 Hz: largest change between half degrees %.1f dB\n", double(largest));
}

namespace {

// A held-out sweep's door: a 4 cm box leaf with 10 mm gaps all round in the middle of a 0.1 m
// wall standing alone (door_scenes.h addFreeWallDoorway), hinged on the wall's mid-plane at its
// side; source and listener 2 m before and behind the doorway's centre.
constexpr float kBox = 0.04f, kGaps = 0.01f, kHalf = 0.45f;
const glm::vec3 kFreeSource{-2.f, 1.05f, 0.f}, kFreeListener{2.f, 1.05f, 0.f};

/// The leaf as a moving object turned `degrees` toward the listener; the wall's faces point
/// out into the air if `outward`, else into the wall. The wall `wall` m thick, the gaps round
/// the leaf `gaps` m, the hinge `hinge` m from the wall's mid-plane (the leaf shut spans
/// +-kBox / 2 about it either way).
SceneDesc freeWallLeaf(double degrees, bool outward, float wall = 0.1f, float gaps = kGaps,
                       float hinge = 0.f) {
  SceneDesc s = doorScene(0.f, Leaf::kNone);
  s.mesh = Mesh{};
  addFreeWallDoorway(s.mesh, wall, outward);
  ObjectDesc door;
  door.name = "leaf";
  s.materials.push_back(s.materials[0]);  // the leaf's own, as a level's door has
  test::addSolidBox(door.mesh, {-0.5f * kBox - hinge, gaps, 0.f},
                    {0.5f * kBox - hinge, 2.1f - gaps, 2.f * (kHalf - gaps)}, 1);
  const glm::quat turn = glm::angleAxis(float(glm::radians(degrees)), glm::vec3(0, 1, 0));
  door.trajectory = {ObjectKeyframe{0.0, glm::vec3(hinge, 0.f, gaps - kHalf), turn}};
  s.objects.push_back(door);
  return s;
}

/// The same leaf in the mesh as an exporter writes it: each face a quad of its own four corners,
/// every coordinate to 1 micrometre (which rim corner a grazing leg clears decides which paths
/// exist: at 12 degrees the way past the rim to the jamb's far corner is free with the corners
/// exact, blocked with them rounded, as in the held-out sweep's files).
SceneDesc freeWallLeafWritten(double degrees, bool outward, float wall = 0.1f, float gaps = kGaps,
                              float hinge = 0.f) {
  SceneDesc s = freeWallLeaf(degrees, outward, wall, gaps, hinge);
  const glm::quat turn = s.objects[0].trajectory[0].rotation;
  const glm::vec3 at = s.objects[0].trajectory[0].position;
  s.objects.clear();
  const float x0 = -0.5f * kBox - hinge, x1 = 0.5f * kBox - hinge, y0 = gaps, y1 = 2.1f - gaps,
              z0 = 0.f, z1 = 2.f * (kHalf - gaps);
  const glm::vec3 faces[6][4] = {
      {{x0, y0, z0}, {x0, y0, z1}, {x0, y1, z1}, {x0, y1, z0}},
      {{x1, y0, z0}, {x1, y1, z0}, {x1, y1, z1}, {x1, y0, z1}},
      {{x0, y0, z0}, {x1, y0, z0}, {x1, y0, z1}, {x0, y0, z1}},
      {{x0, y1, z0}, {x0, y1, z1}, {x1, y1, z1}, {x1, y1, z0}},
      {{x0, y0, z0}, {x0, y1, z0}, {x1, y1, z0}, {x1, y0, z0}},
      {{x0, y0, z1}, {x1, y0, z1}, {x1, y1, z1}, {x0, y1, z1}}};
  for (const auto& face : faces) {
    const auto base = uint32_t(s.mesh.vertices.size());
    for (const glm::vec3& v : face)
      s.mesh.vertices.push_back(glm::round((turn * v + at) * 1e6f) / 1e6f);
    for (const std::array<uint32_t, 3>& t : {std::array<uint32_t, 3>{0, 1, 2}, {0, 2, 3}}) {
      s.mesh.triangles.push_back({base + t[0], base + t[1], base + t[2]});
      s.mesh.materialIndex.push_back(1);
    }
  }
  return s;
}

/// The direct sound re free field (dB) as dpc-demo renders it: the engine's frame, its listener
/// 0.3 m in radius.
Bands freeWallLevel(SceneDesc s, glm::vec3 listener = kFreeListener) {
  s.sources[0].position = kFreeSource;
  s.listeners[0].radius = 0.3f;
  Simulation sim(s);
  sim.runFrame(listener);
  const float r = glm::distance(kFreeSource, listener);
  return decibels(sim.result(0).direct.intensity * float(4.0 * kPi * r * r));
}

/// freeWallLeaf's leaf point (x across its thickness from its mid-plane, z along its width from
/// the hinge) turned `degrees` toward the listener, in the wall's cross-section (y dropped).
glm::dvec2 freeLeafPoint(double x, double z, double degrees) {
  const double a = glm::radians(degrees);
  return {x * std::cos(a) + z * std::sin(a), kGaps - kHalf - x * std::sin(a) + z * std::cos(a)};
}

/// The slits of freeWallLeaf ajar (wall faces x = +-0.05): the latch opening from the jamb's
/// listener-side corner to the nearest point of the leaf, as deep as the rim stands within the
/// reveal; the hinge gap, narrowing as the leaf's listener-side hinge corner turns toward the
/// jamb; the gaps over and under the leaf in 20 pieces each, 10 mm and as deep as the leaf
/// stands under the lintel, or from the leaf's source-side edge to the lintel's listener-side
/// corner once it stands out.
std::vector<Slit> freeWallOpenings(double degrees) {
  constexpr double kFace = 0.05, kLeaf = 2.0 * (kHalf - kGaps), kTop = 2.1 - kGaps;
  const glm::dvec2 jamb(kFace, kHalf), back = freeLeafPoint(-0.5 * kBox, kLeaf, degrees),
                                       front = freeLeafPoint(0.5 * kBox, kLeaf, degrees);
  const glm::dvec2 e = front - back;  // the rim face: nearest point to the jamb's corner
  const glm::dvec2 rim = back + std::clamp(glm::dot(jamb - back, e) / glm::dot(e, e), 0.0, 1.0) * e;
  const double throat = glm::distance(jamb, rim),
               rimDepth = std::clamp(kFace - back.x, 0.0, double(kBox));
  const double mid = 0.5 * (jamb.y + rim.y),
               hinge = kGaps - 0.5 * kBox * std::sin(glm::radians(degrees));
  const double x = 0.5 * (jamb.x + rim.x);
  std::vector<Slit> out = {
      {{x, kGaps, mid}, {x, kTop, mid}, throat, rimDepth},
      {{0, kGaps, -kHalf + 0.5 * hinge}, {0, kTop, -kHalf + 0.5 * hinge}, hinge, kBox}};
  constexpr int kPieces = 20;
  for (int i = 0; i < kPieces; ++i) {
    const double z0 = kLeaf * i / kPieces, z1 = kLeaf * (i + 1) / kPieces;
    const glm::dvec2 s0 = freeLeafPoint(-0.5 * kBox, z0, degrees),
                     s1 = freeLeafPoint(-0.5 * kBox, z1, degrees);
    const glm::dvec2 c = 0.5 * (s0 + s1);
    const double out_of_wall = c.x - kFace;
    const double w = out_of_wall <= 0.0 ? kGaps : std::hypot(out_of_wall, kGaps);
    const double depth = std::clamp(-out_of_wall, 0.0, double(kBox));
    for (double y : {0.5 * w, 2.1 - 0.5 * w})
      out.push_back({{c.x, y, s0.y}, {c.x, y, s1.y}, w, depth});
  }
  return out;
}

}  // namespace

TEST_CASE("Door swing: a box leaf centred in a wall standing alone, swung toward the listener, "
          "never falls below shut at 63-500 Hz nor rises above the open doorway",
          "[diffraction][door]") {
  // The leaf turned 0-30 degrees toward the listener, as a moving object and in the mesh, the
  // leaf on the line of sight. From about 10 degrees the rim stands 8-12 cm from the jamb's far
  // corner and past the wall's face: below 500 Hz, where such an opening is under a wavelength
  // over 2 and passes as a slit, opening wider only passes more (the slit model's transmission
  // grows with the width), so the level never falls below shut (1 dB: the probes resolve widths
  // to 5 %; 2 dB for the leaf in the mesh, whose latch gap at 3 degrees the probe reads 8.8 mm
  // wide against 9.6 mm for the same leaf as an object, 1.7 dB below shut: docs/validation.md).
  // The way round the rim must not be given up to the leaf's top channel, whose edge merely
  // ends at the rim's corner (engine/openings.cpp mouthOf). Nor may the leaf, whose faces reflect
  // away from the listener at these angles, add to the open doorway's direct sound in any band
  // beyond the lit-side ripple of its edges (+1.37 dB): the way round a wide opening's rim is
  // held at the rim's own chain (chain_sum.cpp wideOpeningGain), never above.
  for (bool outward : {true, false}) {
    SceneDesc open = freeWallLeaf(0.0, outward);
    open.objects.clear();
    const Bands openLevel = freeWallLevel(open);
    const Bands shutObject = freeWallLevel(freeWallLeaf(0.0, outward));
    const Bands shutMesh = freeWallLevel(freeWallLeafWritten(0.0, outward));
    printLevels("shut: object / mesh (dB)", {&shutObject, &shutMesh}, 4);
    for (double degrees = 1.0; degrees <= 30.0; degrees += 1.0) {
      const Bands object = freeWallLevel(freeWallLeaf(degrees, outward));
      const Bands mesh = freeWallLevel(freeWallLeafWritten(degrees, outward));
      char label[96];
      std::snprintf(label, sizeof label, "leaf ajar %4.1f deg toward L: object / mesh (dB)",
                    degrees);
      printLevels(label, {&object, &mesh}, 4);
      for (int b = 0; b < kNumBands; ++b) {
        INFO(degrees << " degrees, band " << b << (outward ? "" : ", faces inward"));
        if (b <= 3) CHECK(object[b] > shutObject[b] - 1.f);
        if (b <= 3) CHECK(mesh[b] > shutMesh[b] - 2.f);
        CHECK(object[b] <= openLevel[b] + 1.37f);
        CHECK(mesh[b] <= openLevel[b] + 1.37f);
      }
    }
  }
}

TEST_CASE(
    "Door swing: beside the doorway, a box leaf in a wall standing alone ajar 1-12 degrees "
    "passes what the slit model of its openings says, and never steps",
    "[diffraction][door][heavy]") {
  // The listener 1 m off the doorway's axis, past the latch jamb, the leaf swung toward it: the
  // opening between its rim and the jamb's corner (1 to 12 cm) is seen at a slant from both
  // sides. Tolerance: 3 dB per octave at 63-125 Hz against the slit model, as for the leaf in
  // the thick wall above, and never more than 3 dB between neighbouring degrees (the model's own
  // steps are under 1 dB here). Before, the gap probe read the opening as a free edge at 7-8
  // degrees (the open doorway's level, 11 dB above the model at 63 Hz) and counted it twice at
  // 9 degrees (from the jamb and from the rim: +4.1 dB), a step of 20 dB from 6 to 7 degrees.
  const MouthImpedance zr;
  const glm::vec3 beside = kFreeListener + glm::vec3(0.f, 0.f, 1.f);
  Bands lastObject{}, lastMesh{};
  for (double degrees = 1.0; degrees <= 12.0; degrees += 1.0) {
    const Bands object = freeWallLevel(freeWallLeaf(degrees, true), beside);
    const Bands mesh = freeWallLevel(freeWallLeafWritten(degrees, true), beside);
    const Bands model =
        modelLevels(freeWallOpenings(degrees), zr, glm::dvec3(kFreeSource), glm::dvec3(beside));
    char label[96];
    std::snprintf(label, sizeof label, "leaf ajar %4.1f deg, beside: object / mesh / model (dB)",
                  degrees);
    printLevels(label, {&object, &mesh, &model}, 4);
    for (int b = 0; b <= 1; ++b) {
      INFO(degrees << " degrees, band " << b);
      CHECK(std::abs(object[b] - model[b]) < 3.f);
      CHECK(std::abs(mesh[b] - model[b]) < 3.f);
      if (degrees > 1.0) CHECK(std::abs(object[b] - lastObject[b]) <= 3.f);
      if (degrees > 1.0) CHECK(std::abs(mesh[b] - lastMesh[b]) <= 3.f);
    }
    lastObject = object;
    lastMesh = mesh;
  }
}

TEST_CASE(
    "Door swing: beside the doorway, a box leaf in a wall standing alone swung 1-29 degrees "
    "toward the source passes what the slit model of its openings says, and never falls below "
    "shut",
    "[diffraction][door][heavy]") {
  // The listener 1 m off the axis past the latch jamb, the leaf swung away from it: from about
  // 5 degrees the rim stands out of the reveal on the source's side, and the way to the jamb's
  // corner passes between the rim and the wall's face (3 to 40 cm), which the source sees at a
  // slant past the rim. The model is the toward-listener leaf's mirrored across the wall
  // (freeWallOpenings, x negated): the same leaf turned the other way, whose openings face the
  // source. Tolerance: 3 dB per octave at 63-125 Hz against it where its slits are at least 8
  // times as long as wide (to 15 degrees), as above (found within 1.8 dB); never below shut
  // (1 dB, as above) to 29 degrees; never more than 3 dB between neighbouring degrees to 26
  // degrees, while the rim hides the jamb's far corner from the source (at 27 the line from
  // the source to that corner clears the rim by 2 mm and the corner's own first-order field
  // takes over, 7 dB louder at 63 Hz: the rim's lit-side transition is not modelled for a
  // moving object's edge, docs/validation.md). Before, every first-order path was blocked by
  // the leaf and the chain round the rim and the jamb was refused as threading a gap: 9-26
  // degrees read up to 7 dB below shut (-22.1 against -14.5 dB at 63 Hz), 12 dB below the model.
  const MouthImpedance zr;
  const glm::vec3 beside = kFreeListener + glm::vec3(0.f, 0.f, 1.f);
  const Bands shutObject = freeWallLevel(freeWallLeaf(0.0, true), beside);
  const Bands shutMesh = freeWallLevel(freeWallLeafWritten(0.0, true), beside);
  printLevels("shut, beside: object / mesh (dB)", {&shutObject, &shutMesh}, 4);
  Bands lastObject = shutObject, lastMesh = shutMesh;
  for (double degrees = 1.0; degrees <= 29.0; degrees += 1.0) {
    const Bands object = freeWallLevel(freeWallLeaf(-degrees, true), beside);
    const Bands mesh = freeWallLevel(freeWallLeafWritten(-degrees, true), beside);
    std::vector<Slit> slits = freeWallOpenings(degrees);
    for (Slit& s : slits) {  // mirrored across the wall's mid-plane x = 0
      s.a.x = -s.a.x;
      s.b.x = -s.b.x;
    }
    const Bands model = modelLevels(slits, zr, glm::dvec3(kFreeSource), glm::dvec3(beside));
    char label[96];
    std::snprintf(label, sizeof label, "leaf %4.1f deg toward S, beside: object / mesh / model",
                  degrees);
    printLevels(label, {&object, &mesh, &model}, 4);
    for (int b = 0; b <= 1; ++b) {
      INFO(degrees << " degrees toward the source, band " << b);
      if (degrees <= 15.0) CHECK(std::abs(object[b] - model[b]) < 3.f);
      if (degrees <= 15.0) CHECK(std::abs(mesh[b] - model[b]) < 3.f);
      CHECK(object[b] > shutObject[b] - 1.f);
      CHECK(mesh[b] > shutMesh[b] - 1.f);
      if (degrees <= 26.0) CHECK(std::abs(object[b] - lastObject[b]) <= 3.f);
      if (degrees <= 26.0) CHECK(std::abs(mesh[b] - lastMesh[b]) <= 3.f);
    }
    lastObject = object;
    lastMesh = mesh;
  }
}

TEST_CASE(
    "Door swing: a box leaf whose rim's leg runs along its own end face reads the same in the "
    "mesh as a moving object",
    "[diffraction][door]") {
  // A 0.2 m wall with 20 mm gaps, the leaf swung 12-16 degrees toward the source, the listener
  // on the axis: near 13.5 degrees the leg from the source to the rim's listener-side corner runs
  // along the leaf's end face and clears its other corner by about a millimetre. That leg is
  // free (the leaf as an object keeps it, and so must the mesh), not a gap between the leaf's
  // own two faces: the threaded-leg test's ray across the leg, started a millimetre to the
  // corner's side, began behind the corner and read the end face and the leaf's front as a
  // gap its slits carried. Tolerance: 1 dB per octave at 63 Hz-1 kHz, the held-out sweep's
  // bound for one leaf in two representations (the probes resolve widths to 5 %); and, so that
  // two representations wrong alike do not pass, each never below its own leaf shut at
  // 63-500 Hz (1 dB, as above: an opening 20 cm wide passes more than the closed gaps). Before,
  // the mesh read -33 dB at 63 Hz where the object and the neighbouring angles read -6.7 dB.
  const Bands shutObject = freeWallLevel(freeWallLeaf(0.0, true, 0.2f, 0.02f, -0.5f * kBox));
  const Bands shutMesh = freeWallLevel(freeWallLeafWritten(0.0, true, 0.2f, 0.02f, -0.5f * kBox));
  printLevels("shut, 0.2 m wall: object / mesh", {&shutObject, &shutMesh}, 5);
  for (double degrees = 12.0; degrees <= 16.0; degrees += 0.5) {
    const Bands object = freeWallLevel(freeWallLeaf(-degrees, true, 0.2f, 0.02f, -0.5f * kBox));
    const Bands mesh =
        freeWallLevel(freeWallLeafWritten(-degrees, true, 0.2f, 0.02f, -0.5f * kBox));
    char label[96];
    std::snprintf(label, sizeof label, "leaf %4.1f deg toward S, 0.2 m wall: object / mesh",
                  degrees);
    printLevels(label, {&object, &mesh}, 5);
    for (int b = 0; b <= 4; ++b) {
      INFO(degrees << " degrees toward the source, band " << b);
      CHECK(std::abs(object[b] - mesh[b]) <= 1.f);
      if (b <= 3) CHECK(object[b] > shutObject[b] - 1.f);
      if (b <= 3) CHECK(mesh[b] > shutMesh[b] - 1.f);
    }
  }
}

TEST_CASE(
    "Door swing: beside the doorway, a box leaf in a 0.2 m wall keeps its latch opening while "
    "its rim crosses the wall's face",
    "[diffraction][door]") {
  // Hinged at its source-side face and swung 6-10 degrees toward the source, the leaf's rim
  // leaves the reveal near 8 degrees: its listener-side corner passes the wall's face a few
  // millimetres from the jamb's corner, and the opening between them (13 mm) is no longer the
  // reveal's channel but the rim's, beside a leg that runs almost along the wall's face. The
  // listener 1 m off the axis past the latch jamb. The opening only widens as the leaf turns,
  // so the level steps by no more than 3 dB per quarter degree at 63-250 Hz (the bound of the
  // swings above) and never falls below shut (1 dB). Before, the fan looking across the rim's
  // leg for the opening reached 60 degrees from the leg, short of the wall's face 3 mm ahead:
  // at 8 degrees the opening was found by nothing and the level fell 10 dB for that angle
  // (-22.5 dB at 63 Hz between -10.5 and -12.3), and read 6 dB too loud 0.5 m off the axis.
  const glm::vec3 beside = kFreeListener + glm::vec3(0.f, 0.f, 1.f);
  auto leaf = [&](double degrees) {
    return freeWallLevel(freeWallLeaf(-degrees, true, 0.2f, kGaps, -0.5f * kBox), beside);
  };
  const Bands shut = leaf(0.0);
  Bands last = leaf(6.0);
  for (double degrees = 6.25; degrees <= 10.0; degrees += 0.25) {
    const Bands level = leaf(degrees);
    char label[96];
    std::snprintf(label, sizeof label, "leaf %5.2f deg toward S, 0.2 m wall, beside", degrees);
    printLevels(label, {&level}, 4);
    for (int b = 0; b <= 2; ++b) {
      INFO(degrees << " degrees toward the source, band " << b);
      CHECK(std::abs(level[b] - last[b]) <= 3.f);
      CHECK(level[b] > shut[b] - 1.f);
    }
    last = level;
  }
}
