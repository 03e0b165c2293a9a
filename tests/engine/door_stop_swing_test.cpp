// A leaf closed against a door stop, opened a few degrees: the box leaf 4 cm thick in the
// middle of a 0.2 m wall's doorway, hinged on its centre line at the jamb, a stop 2 cm deep with
// a 2 cm lip behind it (on the listener's side) or before it, turned away from the stop 0.5-8
// degrees, as a moving object and written into the static mesh. Up to about 2 degrees the
// latch gap is L-shaped (along the leaf's latch face, then between its face and the stop);
// from 3 degrees its latch rim has left the reveal and the opening is the slanted gap between
// the rim and the jamb's corner (5 mm at 3 degrees, 4 cm at 5), past which the stop's lip
// stands beside the way to the listener. Before engine/turned_legs.h the jamb's path was
// dropped there (the stop blocks its leg) and the leaf's latch channel had nothing across its
// face: opened 3-4.5 degrees the leaf read 5-10 dB below shut, 10-15 dB below the slit model of
// its openings.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <glm/geometric.hpp>
#include <vector>

#include "engine/diffraction.h"
#include "tests/engine/door_scenes.h"
#include "tests/engine/slit_model.h"

using namespace dpc;
using namespace dpc::door_test;

namespace {

constexpr float kThickness = 0.04f, kWall = 0.2f, kLip = 0.02f, kGap = 0.005f;

/// Where the leaf's front face stands shut: 1 cm into the wall from the face the stop is not on.
float leafFront(float side) { return side > 0.f ? 6.01f : 6.f + kWall - 0.01f - kThickness; }

/// The leaf's point (x across its thickness from its centre line, z along its width from the
/// hinge gap) in the room, turned `degrees` away from the stop on `side` (y dropped).
glm::dvec3 leafPoint(double x, double z, double degrees, float side) {
  const double a = glm::radians(degrees) * (side > 0.f ? -1.0 : 1.0);
  const double centre = double(leafFront(side)) + 0.5 * kThickness;
  return {centre + x * std::cos(a) + z * std::sin(a), 0.0,
          kDoorZ0 + kGap - x * std::sin(a) + z * std::cos(a)};
}

/// The slits of the leaf ajar without the stop, computed from its geometry alone: the latch
/// gap (5 mm as deep as the leaf while its rim on the side it turns from is in the reveal;
/// then the opening from that rim to the wall's corner, without depth), the hinge gap
/// (narrowing as the leaf's corner turns toward the jamb), and the slot under the lintel in 20
/// pieces (the 5 mm gap as deep as the leaf in the reveal, the opening to the lintel's corner
/// where the leaf stands out of the wall).
std::vector<Slit> openings(double degrees, float side) {
  constexpr double kWidth = kDoorWidth - 2 * kGap, kHeight = kDoorHeight - kGap;
  const double back = side > 0.f ? 0.5 * kThickness : -0.5 * kThickness;  // the rim's side
  const double face = side > 0.f ? 6.0 : 6.0 + kWall;  // the wall's face it turns out of
  const double centre = double(leafFront(side)) + 0.5 * kThickness;
  auto outside = [&](const glm::dvec3& p) { return side > 0.f ? face - p.x : p.x - face; };
  std::vector<Slit> out;
  const glm::dvec3 rim = leafPoint(back, kWidth, degrees, side);
  const glm::dvec3 jamb(face, 0.0, kDoorZ0 + kDoorWidth);
  if (outside(rim) > 0.0) {
    const glm::dvec3 c = 0.5 * (rim + jamb);
    out.push_back({{c.x, 0, c.z}, {c.x, kHeight, c.z}, glm::length(rim - jamb), 0.0});
  } else {
    const double z = kDoorZ0 + kDoorWidth - 0.5 * kGap;
    out.push_back({{centre, 0, z}, {centre, kHeight, z}, kGap, kThickness});
  }
  const double hinge = kGap - 0.5 * kThickness * std::sin(glm::radians(degrees));
  if (hinge > 5e-4)
    out.push_back({{centre, 0, kDoorZ0 + hinge / 2}, {centre, kHeight, kDoorZ0 + hinge / 2},
                   hinge, kThickness});
  constexpr int kPieces = 20;
  for (int i = 0; i < kPieces; ++i) {
    const double z0 = kWidth * i / kPieces, z1 = kWidth * (i + 1) / kPieces;
    const glm::dvec3 p0 = leafPoint(back, z0, degrees, side);
    const glm::dvec3 p1 = leafPoint(back, z1, degrees, side);
    const double past = outside(0.5 * (p0 + p1));
    if (past <= 0.0) {
      const glm::dvec3 c0 = leafPoint(0, z0, degrees, side), c1 = leafPoint(0, z1, degrees, side);
      const double y = kDoorHeight - kGap / 2;
      out.push_back({{c0.x, y, c0.z}, {c1.x, y, c1.z}, kGap, kThickness});
    } else {
      const double w = std::hypot(past, kGap), y = kDoorHeight - 0.5 * w;
      out.push_back({{face, y, p0.z}, {face, y, p1.z}, w, 0.0});
    }
  }
  return out;
}

/// The slit model of the widest the gaps can be: the latch gap a slit without depth as wide as
/// the leaf's free rim has moved, the others as shut (the stop and the leaf's depth only take
/// from that).
Bands widestGaps(double degrees, float side, const MouthImpedance& zr) {
  std::vector<Slit> widest =
      perimeterSlits(kGap, double(leafFront(side)) + 0.5 * kThickness, kThickness);
  const double latch = kGap + kDoorWidth * std::sin(glm::radians(degrees));
  const double z = kDoorZ0 + kDoorWidth - 0.5 * latch;
  widest[1] = {{widest[1].a.x, 0, z}, {widest[1].a.x, kDoorHeight, z}, latch, 0.0};
  return modelLevels(widest, zr);
}

}  // namespace

TEST_CASE(
    "Door stop: a leaf closed against a stop and opened half a degree at a time is never "
    "quieter than shut, and from 3 degrees passes what its openings pass",
    "[diffraction][door][heavy]") {
  // 0.5-8 degrees by half degrees, the stop on either side, the leaf as a moving object and in
  // the static mesh. (1) Opening only widens the latch gap: never more than 1.5 dB below shut
  // at 63 Hz-1 kHz (the hinge gap narrows as the leaf turns, 4.7 to 4.3 mm at 1 degree, 0.4 dB
  // of one of three slits, and the probe resolves a width to 5 %, 0.2 dB; found 0.0). (2) At
  // most the slit model of the widest the gaps can be, +3 dB as for a closed leaf. (3) From 3
  // degrees, with the latch rim out of the reveal, within 3 dB above and 6 dB below the slit
  // model of the openings without the stop at 63-250 Hz: the model leaves out the stop, whose
  // lip the way from the opening to the listener grazes (a half-plane takes 6 dB at its shadow
  // boundary; found -1.7 to +0.9 dB). (4) The object and the same leaf in the mesh within
  // 1.5 dB at 63-500 Hz (found 1.1; at 1 kHz up to 1.5, where the object's rims and the
  // mesh's edges take different ways).
  const MouthImpedance zr;
  for (float side : {1.f, -1.f}) {
    const float x0 = leafFront(side);
    SceneDesc shut = objectLeafScene(kWall, kGap, kThickness, x0 + 0.5f * kThickness);
    addDoorStop(shut.mesh, kGap, kThickness, x0, side, kLip);
    const Bands closed = decibels(directLevel(shut));
    for (double degrees = 0.5; degrees <= 8.0; degrees += 0.5) {
      const SceneDesc scene = swungAwayFromStop(shut, side, float(degrees));
      const Bands object = decibels(directLevel(scene));
      const Bands mesh = decibels(directLevel(objectsInMesh(scene)));
      const Bands model = modelLevels(openings(degrees, side), zr);
      const Bands upper = widestGaps(degrees, side, zr);
      char label[112];
      std::snprintf(label, sizeof label,
                    "stop %s, ajar %3.1f deg: object / in the mesh / shut / model / upper (dB)",
                    side > 0.f ? "behind" : "before", degrees);
      printLevels(label, {&object, &mesh, &closed, &model, &upper}, 5);
      for (int b = 0; b <= 4; ++b) {
        INFO("stop side " << side << ", " << degrees << " degrees, band " << b);
        for (const Bands* l : {&object, &mesh}) {
          CHECK((*l)[b] >= closed[b] - 1.5f);
          CHECK((*l)[b] <= upper[b] + 3.f);
          if (degrees >= 3.0 && b <= 2) {
            CHECK((*l)[b] - model[b] < 3.f);
            CHECK((*l)[b] - model[b] > -6.f);
          }
        }
        if (b <= 3) CHECK(std::abs(object[b] - mesh[b]) < 1.5f);
      }
    }
  }
}
