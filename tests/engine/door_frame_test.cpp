// Doors in their frames: a leaf set in a thick wall (a sheet, a 1 mm plate, a 6 mm pane, a
// 4 cm box), a box leaf closing against a door stop (an L-shaped gap), seen on the line of
// sight and off the axis, a box leaf that is a moving object, and one heard from above the
// lintel's height. The closed levels follow the slit model with depth (tests/engine/
// slit_model.h, computed on its own) and never exceed the open doorway.
#include <algorithm>
#include <array>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <glm/gtc/quaternion.hpp>
#include <vector>

#include "engine/diffraction.h"
#include "engine/embree_tracer.h"
#include "testing/test_scenes.h"
#include "tests/engine/door_scenes.h"
#include "tests/engine/slit_model.h"

using namespace dpc;
using namespace dpc::door_test;

TEST_CASE("Door gaps: a leaf set in a thick wall passes its gaps, a box leaf through their depth",
          "[diffraction][door][heavy]") {
  // A real door: its leaf (a sheet, a solid 1 mm plate, a 6 mm glass pane, or a box 4 cm thick)
  // set in a wall 0.1 or 0.2 m thick,
  // flush with either face or in the middle, gaps of 5, 10 and 20 mm round it. Before, a box
  // leaf passed nothing (its two rims each hid the gap from the other side), and the jambs'
  // edges, seen through the gap beside a sheet, took the closed door to the open doorway's
  // level at 250-500 Hz. Closed stays below the open doorway and the free field in every band,
  // and within the 3 dB of the slit model with the leaf's thickness as the slit's depth
  // (Mechel's transmission line, computed here on its own; found: within 1.0 dB in every band,
  // the box's half-wave resonance at 4 kHz included). The slits' mutual loading is taken as
  // for slits in a sheet, by dpc and this model alike: deep slits' mouths load each other on
  // both sides, which neither holds; the 63 and 125 Hz levels rest on that.
  const MouthImpedance zr;
  for (float wall : {0.1f, 0.2f}) {
    const Bands open = decibels(directLevel(thickDoorwayScene(wall, false)));
    for (float thickness : {0.f, 0.001f, 0.006f, 0.04f})
      for (float set : {0.f, 0.5f, 1.f})  // flush with the source's face, middle, far face
        for (float gap : {0.005f, 0.01f, 0.02f}) {
          const float x = 6.f + 0.5f * thickness + set * (wall - thickness);
          const Bands closed = decibels(directLevel(recessedLeafScene(wall, gap, thickness, x)));
          const Bands model = modelLevels(perimeterSlits(gap, x, thickness), zr);
          char label[96];
          std::snprintf(label, sizeof label, "wall %.1f m, leaf %2.0f mm at x %.2f, gap %2.0f mm",
                        double(wall), 1e3 * double(thickness), double(x), 1e3 * double(gap));
          checkClosedAgainstModel(label, closed, open, model);
        }
  }
}

TEST_CASE("Door gaps: a box leaf closed against a door stop passes its L-shaped gaps",
          "[diffraction][door][heavy]") {
  // Real doors close against a stop: a strip round the frame that the leaf's face overlaps, so
  // each gap runs along the leaf's side and turns between its face and the stop. Before, such
  // a door passed nothing at all (from the mouth by the stop, the other room lies behind the
  // stop). The model (computed here on its own) takes the bent slit as a straight one as deep
  // as its centre line is long: the leaf's thickness plus the stop's lip (from the middle of
  // the side gap to the stop's edge, lip - gap / 2, and across the leaf's thickness plus half
  // the gap between the leaf and the stop); dpc's depth runs along the channel and then square
  // to it (engine/edge_path.h channelDepth), the same length with the gaps equally wide, as
  // here. Within the 3 dB in every band (found: 1.0 dB), below the open doorway and
  // the free field; the stop on either side (the listener's room or the source's).
  const MouthImpedance zr;
  constexpr float kThickness = 0.04f;
  for (float wall : {0.1f, 0.2f}) {
    const Bands open = decibels(directLevel(thickDoorwayScene(wall, false)));
    for (float side : {1.f, -1.f})
      for (float lip : {0.015f, 0.025f})
        for (float gap : {0.003f, 0.005f, 0.01f}) {
          const float x0 = side > 0.f ? 6.01f : 6.f + wall - 0.01f - kThickness;
          const SceneDesc scene = stoppedLeafScene(wall, gap, kThickness, x0, side, lip);
          const Bands closed = decibels(directLevel(scene));
          const Bands model =
              modelLevels(perimeterSlits(gap, x0 + 0.5f * kThickness, kThickness + lip), zr);
          char label[96];
          std::snprintf(label, sizeof label, "wall %.1f m, stop %s, lip %2.0f mm, gap %2.0f mm",
                        double(wall), side > 0.f ? "behind" : "before", 1e3 * double(lip),
                        1e3 * double(gap));
          checkClosedAgainstModel(label, closed, open, model);
        }
  }
}

TEST_CASE("Door gaps: a leaf proud of the wall's face, or flush with both faces of a wall as thick",
          "[diffraction][door][heavy]") {
  // Where a model puts the leaf: a few millimetres proud of the wall's face (toward either
  // room), or a box exactly as thick as the wall, flush with both its faces (a game level's
  // door is often a box that fills the hole), or a sheet in front of the wall's face. Before,
  // against the model below: a box leaf 3 or 10 mm proud read 7.6-9.9 dB above it at 63-1000 Hz
  // (the channel's depth was measured from inside the leaf: a slit in a sheet); a box as thick
  // as a 4 or 10 cm wall, flush with both faces, read the open doorway, up to 27 dB above it
  // (the path round the reveal's two corners ran between the leaf and the reveal, and no test
  // saw the leaf 5 mm off: both of its side tests lay inside a solid); a sheet 3 or 5 mm in
  // front of a 0.2 m wall's face read up to 15.7 dB above it (its rim's probe, in the sheet's
  // plane, passed the wall's corner between two coarse widths: a 21 cm slit). A sheet 10 mm in
  // front still reads up to 6.3 dB above the model (its rim's probe finds 49 mm, the wall
  // corner's 7.5 mm, and the rim's, first in the list, carries the slit; docs/validation.md). Model: the slit model with depth (computed here on its own), the
  // slit's depth the leaf's overlap with the reveal, a sheet's slit as wide as the opening
  // from its rim to the wall's corner (the narrowest; depth 0). Within the 3 dB.
  const MouthImpedance zr;
  constexpr float kGap = 0.005f;
  struct Placement {
    float wall, thickness, x0;  // m: the leaf from x0 to x0 + thickness (the wall 6 .. 6 + wall)
  };
  std::vector<Placement> cases;
  for (float wall : {0.04f, 0.1f, 0.2f})
    for (float proud : {0.003f, 0.01f}) {
      cases.push_back({wall, 0.04f, 6.f - proud});                // proud toward the source
      cases.push_back({wall, 0.04f, 6.f + wall + proud - 0.04f});  // toward the listener
    }
  cases.push_back({0.04f, 0.04f, 6.f});  // flush with both faces
  cases.push_back({0.1f, 0.1f, 6.f});
  for (float wall : {0.04f, 0.2f})  // sheets
    for (float proud : {0.003f, 0.005f, 0.02f}) cases.push_back({wall, 0.f, 6.f - proud});
  for (const Placement& c : cases) {
    const Bands open = decibels(directLevel(thickDoorwayScene(c.wall, false)));
    const float x = c.x0 + 0.5f * c.thickness;
    const Bands closed = decibels(directLevel(recessedLeafScene(c.wall, kGap, c.thickness, x)));
    const float overlap =
        std::max(0.f, std::min(c.x0 + c.thickness, 6.f + c.wall) - std::max(c.x0, 6.f));
    const float proud = std::max(0.f, 6.f - c.x0 - c.thickness);  // a sheet's
    const Bands model = modelLevels(
        perimeterSlits(std::hypot(kGap, proud), x, c.thickness > 0.f ? overlap : 0.f), zr);
    char label[112];
    std::snprintf(label, sizeof label, "wall %.2f m, leaf %2.0f mm from x %.3f, gap %1.0f mm",
                  double(c.wall), 1e3 * double(c.thickness), double(c.x0), 1e3 * double(kGap));
    checkClosedAgainstModel(label, closed, open, model);
  }
}

TEST_CASE("Door gaps: a box leaf in a thick wall seen off the axis with or without a door stop",
          "[diffraction][door][heavy]") {
  // The pairs of "seen from off the axis" below (beside the doorway, past a jamb), the leaf
  // 4 cm thick in a 0.1 m wall, without a stop, or closing against one on the listener's or
  // the source's side (lip 15 mm). The stop's edge and the wall's corner behind it hide the
  // gap's mouth by the stop, so the path leaves round them (engine/channel_turn.h). Before,
  // the stopped doors passed nothing in 9 of these 16 cases and read 3-10 dB below the model
  // in the others (only the far jamb's gap found); the box leaf without a stop read 2-9 dB
  // below it: the blocked line of sight's bound took away the wall's face round the reveal,
  // which the probe had taken for the gaps' far side (engine/gap_probe.cpp findFarSides).
  // Within the 3 dB of the model (as in the test above, depth thickness + lip; found:
  // 2.5 dB). The model leaves out the shadow of the stop's corners, which dpc takes (Kurze and
  // Anderson past the shadow boundary, engine/slit.h): where the 15 mm lip is a wavelength /
  // 2 pi or more (4 and 8 kHz) dpc may read up to 6 dB below it (found: 2.7 dB), never 3 dB
  // above.
  const MouthImpedance zr;
  constexpr float kThickness = 0.04f, kLip = 0.015f, kWall = 0.1f;
  for (float side : {0.f, 1.f, -1.f})  // no stop, behind the leaf, before it
    for (float gap : {0.005f, 0.01f})
      for (const auto& [src, lis] : kOffAxisPairs) {
        const float x0 = side >= 0.f ? 6.01f : 6.f + kWall - 0.01f - kThickness;
        const SceneDesc scene =
            side == 0.f ? recessedLeafScene(kWall, gap, kThickness, x0 + 0.5f * kThickness)
                        : stoppedLeafScene(kWall, gap, kThickness, x0, side, kLip);
        const float depth = kThickness + (side == 0.f ? 0.f : kLip);
        const Bands closed = decibels(directLevel(scene, src, lis));
        const Bands model = modelLevels(perimeterSlits(gap, x0 + 0.5f * kThickness, depth), zr,
                                        glm::dvec3(src), glm::dvec3(lis));
        const char* where = side == 0.f ? "none  " : side > 0.f ? "behind" : "before";
        std::printf("stop %s, gap %2.0f mm, source z %.1f m, listener z %.1f m: dpc, dpc - model (dB)",
                    where, 1e3 * double(gap), double(src.z), double(lis.z));
        for (int b = 0; b < kNumBands; ++b) {
          std::printf(" %5.1f/%+4.1f", double(closed[b]), double(closed[b] - model[b]));
          INFO("stop " << where << ", gap " << gap << ", source z " << src.z << ", band " << b);
          CHECK(closed[b] <= 1e-4f);
          const bool shadowed = side != 0.f && b >= 6;  // 4 and 8 kHz: k lip >= 1
          CHECK(closed[b] - model[b] < 3.f);
          CHECK(closed[b] - model[b] > (shadowed ? -6.f : -3.f));
        }
        std::printf("\n");
      }
}

TEST_CASE("Door gaps: a box leaf that is a moving object passes its gaps as a static one does",
          "[diffraction][door][heavy]") {
  // Games move their doors: the leaf is a scene object, whose own edges have no first-order
  // paths (their rims face the frame within 3 cm, so no chain goes round them either), so the
  // channels along its side faces are not there. The gap then runs along the wall's reveal
  // (0.2 m), which is a channel too; the probe finds the leaf across it and where the leaf
  // stands along it, and the slit is taken there, as deep as the leaf (engine/gap_probe.h,
  // GapShape::depth). Before, the closed object door passed nothing at all. Checked against
  // the slit model with depth, 3 dB per octave as above, and below the open doorway.
  const MouthImpedance zr;
  const Bands open = decibels(directLevel(thickDoorwayScene(0.2f, false)));
  for (float x : {0.02f, 0.1f, 0.18f})
    for (float gap : {0.005f, 0.01f, 0.02f}) {
      const Bands closed = decibels(directLevel(objectLeafScene(0.2f, gap, 0.04f, 6.f + x)));
      const Bands model = modelLevels(perimeterSlits(gap, 6.0 + double(x), 0.04), zr);
      std::printf("object box leaf at x %.2f, gap %2.0f mm: dpc, dpc - model (dB)", 6.0 + double(x),
                  1e3 * double(gap));
      for (int b = 0; b < kNumBands; ++b)
        std::printf(" %5.1f/%+4.1f", double(closed[b]), double(closed[b] - model[b]));
      std::printf("\n");
      for (int b = 0; b < kNumBands; ++b) {
        INFO("leaf at " << x << ", gap " << gap << ", band " << b);
        CHECK(closed[b] <= open[b]);
        CHECK(std::abs(closed[b] - model[b]) < 3.f);
      }
    }
}

namespace {

/// A wall `depth` thick standing alone in the open (x -depth/2 .. depth/2, 60 m square), its
/// doorway 0.9 x 2.1 m (z -0.45 .. 0.45, y 0 .. 2.1) closed by a box leaf 4 cm thick as a moving
/// object, `gap` from the jambs and the lintel, `undercut` above the sill (0, 0: it fills the
/// doorway); no floor: the sill is the wall's own reveal.
SceneDesc wallInTheOpen(float depth, float gap = 0.f, float undercut = 0.f) {
  SceneDesc s = objectLeafScene(depth, 0.f, 0.04f, 0.f);
  s.mesh = Mesh{};
  const float h = 0.5f * depth;
  test::addSolidBox(s.mesh, {-h, -30.f, -30.f}, {h, 0.f, 30.f}, 0);
  test::addSolidBox(s.mesh, {-h, 2.1f, -30.f}, {h, 30.f, 30.f}, 0);
  test::addSolidBox(s.mesh, {-h, 0.f, -30.f}, {h, 2.1f, -0.45f}, 0);
  test::addSolidBox(s.mesh, {-h, 0.f, 0.45f}, {h, 2.1f, 30.f}, 0);
  s.objects[0].mesh = Mesh{};
  test::addSolidBox(s.objects[0].mesh, {-0.02f, undercut, gap - 0.45f},
                    {0.02f, 2.1f - gap, 0.45f - gap}, 0);
  s.objects[0].trajectory[0].position = glm::vec3(0.f);
  return s;
}

}  // namespace

TEST_CASE("Door gaps: a box leaf that fills its doorway exactly passes nothing, object or mesh",
          "[diffraction][door]") {
  // A game level's door is often a box the size of its hole: its top flush with the lintel's
  // underside, its sides with the jambs', standing on the floor. No gap, so no direct sound at
  // all (the oracle: nothing but the leaf stands in the doorway). Before, as a moving object,
  // its faces' channels were probed across a mouth that lay inside the lintel and the jambs,
  // whose faces in front of it the probe took for another edge's shadow: gaps of 35 mm, up to
  // -12.6 dB re free field past the jamb (a held-out sweep), where the same leaf in the mesh
  // was silent (engine/path_slits.cpp coveredFace). In the two rooms below, and in a wall
  // standing alone in the open, its doorway's sill the wall's own reveal (as the sweep had it).
  for (float wall : {0.1f, 0.2f})
    for (const float side : {0.f, 0.6f, 1.5f})  // the listener on the axis, past a jamb, beside
      for (int object = 0; object < 2; ++object) {
        SceneDesc scene = objectLeafScene(wall, 0.f, 0.04f, 6.f + 0.5f * wall);
        if (!object) scene = objectsInMesh(scene);
        const glm::vec3 source = kSource - glm::vec3(0.f, 0.f, 0.5f * side);
        const Bands level = directLevel(scene, source, kListener + glm::vec3(0.f, 0.f, side));
        SceneDesc open = wallInTheOpen(wall);
        if (!object) open = objectsInMesh(open);
        const Bands alone =
            directLevel(open, {-2.f, 1.05f, -0.5f * side}, {2.f, 1.05f, 0.5f * side});
        for (int b = 0; b < kNumBands; ++b) {
          INFO("wall " << wall << ", listener " << side << " m off the axis, "
                       << (object ? "object" : "mesh") << ", band " << b);
          CHECK(level[b] == 0.f);
          CHECK(alone[b] == 0.f);
        }
      }
}

TEST_CASE("Door gaps: a box leaf that is a moving object, heard past the jamb, reads as in the mesh",
          "[diffraction][door]") {
  // The wall in the open above, the leaf 1 cm from the jambs and the lintel with a 1 cm
  // undercut, or sealed but for a 2 cm undercut. The listener 2 m behind the wall, walked from
  // the doorway's axis past the jamb, where the wall hides the line of sight (the source on the
  // axis 2 m before it). The oracle: the same leaf in the static mesh, found within 3 dB of
  // Gomperts' slit model by a held-out sweep. Before, the object lost the slits whose point of
  // least length the jamb hides (past the jamb: 2.8 dB at 63 Hz and 6 dB at 500 Hz below the
  // mesh leaf, nothing at all with the undercut alone), and where the line of sight crossed
  // both the leaf and the jamb (z 0.86-0.9 m) a bound that took the jamb away with the leaf
  // still standing, its own field missing from the sum, silenced it.
  for (const auto& [gap, undercut] : {std::pair(0.01f, 0.01f), std::pair(0.f, 0.02f)}) {
    const SceneDesc object = wallInTheOpen(0.1f, gap, undercut);
    const SceneDesc mesh = objectsInMesh(object);
    for (float z = 0.f; z <= 1.2f; z += 0.04f) {
      const glm::vec3 source{-2.f, 1.05f, 0.f}, listener{2.f, 1.05f, z};
      const Bands o = decibels(directLevel(object, source, listener));
      const Bands m = decibels(directLevel(mesh, source, listener));
      for (int b = 0; b < 5; ++b) {  // 63 Hz - 1 kHz
        INFO("gap " << gap << ", undercut " << undercut << ", listener z " << z << ", band " << b
                    << ": object " << o[b] << ", mesh " << m[b] << " dB");
        CHECK(std::isfinite(m[b]));
        CHECK(std::abs(o[b] - m[b]) < 1.5f);
      }
    }
  }
}

TEST_CASE("Door gaps: a box leaf's undercut wider than the leaf is deep is still its slit",
          "[diffraction][door]") {
  // The wall in the open above, 4 cm thick, the 4 cm box leaf flush with both its faces and
  // tight at the jambs and the lintel, its undercut 30 to 60 mm (a held-out sweep's door); the
  // listener 2 and 5 m behind the wall on the axis. The undercut is a slit as deep as the leaf
  // however wide, until k w passes 2 pi (8 kHz at 43 mm). Before, a channel's gap was at most
  // its face's depth: from 42 mm on the gap was dropped and the closed door read the open
  // doorway (-7.9 dB re free field at 63 Hz against the model's -25.8 at 2 m), and from 50 mm,
  // when kept, the sill's edge path through it (its leg missed by the 30 mm threaded-leg test)
  // owned it as a slit without depth (8 dB above the model). The model: the slit with depth
  // (tests/engine/slit_model.h, computed on its own). Checked: within the 3 dB of it at
  // 63 Hz-2 kHz, monotonic in the gap at 63 Hz-2 kHz, below the open doorway in every band.
  const MouthImpedance zr;
  constexpr double kDepth = 0.04;
  const glm::vec3 source{-2.f, 1.05f, 0.f};
  SceneDesc doorway = wallInTheOpen(float(kDepth));
  doorway.objects.clear();
  for (const float behind : {2.f, 5.f}) {
    const glm::vec3 listener{behind, 1.05f, 0.f};
    const Bands open = decibels(directLevel(doorway, source, listener));
    for (int object = 0; object < 2; ++object) {
      Bands previous(-1e3f);
      for (const double under : {0.03, 0.041, 0.045, 0.06}) {
        SceneDesc scene = wallInTheOpen(float(kDepth), 0.f, float(under));
        if (!object) scene = objectsInMesh(scene);
        const Bands closed = decibels(directLevel(scene, source, listener));
        const std::vector<Slit> slit = {
            {{0, under / 2, -0.45}, {0, under / 2, 0.45}, under, kDepth}};
        const Bands model = modelLevels(slit, zr, glm::dvec3(source), glm::dvec3(listener));
        std::printf("undercut %2.0f mm, %s, listener %.0f m behind: dpc/model (dB)", 1e3 * under,
                    object ? "object" : "mesh", double(behind));
        for (int b = 0; b < kNumBands; ++b)
          std::printf(" %5.1f/%5.1f", double(closed[b]), double(model[b]));
        std::printf("\n");
        for (int b = 0; b < kNumBands; ++b) {
          INFO((object ? "object" : "mesh") << ", undercut " << under << ", listener " << behind
                                            << " m, band " << b << ": dpc " << closed[b]
                                            << ", model " << model[b] << ", open " << open[b]);
          CHECK(closed[b] <= open[b]);
          if (b > 5) continue;
          CHECK(std::abs(closed[b] - model[b]) < 3.f);
          CHECK(closed[b] >= previous[b] - 0.05f);
        }
        previous = closed;
      }
    }
  }
}

TEST_CASE("Door gaps: a box leaf with narrow side gaps, heard beside its doorway, passes its slits",
          "[diffraction][door]") {
  // The wall in the open above, the leaf 3 mm from the jambs and the lintel with a 10 mm
  // undercut (a usual door), as an object and in the mesh; the source and the listener 2 m
  // either side of the wall and 1 m beside the doorway's axis, on the same side of it (the
  // wall hides the line of sight; a held-out sweep's "same" position). Before, the probe read
  // the far jamb's 3 mm gap through legs that meet it at a steep angle as 7.4 mm without depth
  // (no far side found; engine/path_slits.cpp squareWidth): 5.7 to 13.7 dB above the slit
  // model at 63-500 Hz. The model: the slit model with depth (tests/engine/slit_model.h,
  // computed on its own) of the four gaps, 4 cm deep, which radiates from the mouths freely
  // (the reveal's corners left out); within 3 dB per octave at 63-500 Hz.
  const MouthImpedance zr;
  constexpr double kGap = 0.003, kUnder = 0.01, kDepth = 0.04, kTop = 2.1;
  const std::vector<Slit> slits = {
      {{0, kUnder, -0.45 + kGap / 2}, {0, kTop - kGap, -0.45 + kGap / 2}, kGap, kDepth},
      {{0, kUnder, 0.45 - kGap / 2}, {0, kTop - kGap, 0.45 - kGap / 2}, kGap, kDepth},
      {{0, kTop - kGap / 2, -0.45 + kGap}, {0, kTop - kGap / 2, 0.45 - kGap}, kGap, kDepth},
      {{0, kUnder / 2, -0.45 + kGap}, {0, kUnder / 2, 0.45 - kGap}, kUnder, kDepth}};
  const glm::vec3 source{-2.f, 1.05f, -1.f}, listener{2.f, 1.05f, -1.f};
  const Bands model = modelLevels(slits, zr, glm::dvec3(source), glm::dvec3(listener));
  for (int object = 0; object < 2; ++object) {
    SceneDesc scene = wallInTheOpen(0.1f, float(kGap), float(kUnder));
    if (!object) scene = objectsInMesh(scene);
    const Bands level = decibels(directLevel(scene, source, listener));
    std::printf("3 mm side gaps, 10 mm undercut, %s, beside the doorway: dpc - model (dB)",
                object ? "object" : "mesh");
    for (int b = 0; b < kNumBands; ++b) std::printf(" %+5.1f", double(level[b] - model[b]));
    std::printf("\n");
    for (int b = 0; b < 4; ++b) {
      INFO((object ? "object" : "mesh") << ", band " << b << ": dpc " << level[b] << ", model "
                                        << model[b] << " dB");
      CHECK(std::abs(level[b] - model[b]) < 3.f);
    }
  }
}

namespace {

/// The direct sound from kSource to kListener with its line of sight blocked (nothing of it
/// passes), for EdgeDiffraction::apply.
DirectSound blockedDirect() {
  const glm::vec3 v = kListener - kSource;
  DirectSound d;
  d.visible = false;
  d.distance = glm::length(v);
  d.delaySeconds = d.distance / kC;
  d.direction = -v / d.distance;
  d.intensity = Bands(0.f);
  return d;
}

}  // namespace

TEST_CASE("Door gaps: a moving-object leaf closed against a door stop passes its L-shaped gaps",
          "[diffraction][door]") {
  // A game's door is a scene object, and real frames have a stop. The object's narrow faces
  // carry channels that turn round the stop's edges in the mesh (engine/object_edges.h
  // objectChannels): before, such a door passed nothing at all (-300 dB in every band, the
  // reveal's channel shut by the stop). Against the same slit model as the static leaf with a
  // stop (3 dB per octave), below the open doorway; and equal to that static leaf within
  // 0.5 dB (the same gaps: the two paths differ only in where their edges come from).
  const MouthImpedance zr;
  constexpr float kThickness = 0.04f, kWall = 0.2f, kLip = 0.02f;
  const Bands open = decibels(directLevel(thickDoorwayScene(kWall, false)));
  for (float side : {1.f, -1.f})
    for (float gap : {0.005f, 0.01f}) {
      const float x0 = side > 0.f ? 6.01f : 6.f + kWall - 0.01f - kThickness;
      SceneDesc scene = objectLeafScene(kWall, gap, kThickness, x0 + 0.5f * kThickness);
      addDoorStop(scene.mesh, gap, kThickness, x0, side, kLip);
      const Bands closed = decibels(directLevel(scene));
      const Bands fixed = decibels(directLevel(stoppedLeafScene(kWall, gap, kThickness, x0, side,
                                                                kLip)));
      const Bands model =
          modelLevels(perimeterSlits(gap, x0 + 0.5f * kThickness, kThickness + kLip), zr);
      char label[96];
      std::snprintf(label, sizeof label, "object leaf, stop %s, gap %2.0f mm",
                    side > 0.f ? "behind" : "before", 1e3 * double(gap));
      checkClosedAgainstModel(label, closed, open, model);
      for (int b = 0; b < kNumBands; ++b) {
        INFO(label << ", band " << b);
        CHECK(std::abs(closed[b] - fixed[b]) < 0.5f);
      }
      // The edges a pair reports (the response snapshot indexes the static edges with them):
      // an object channel's edges are the object's, not among them.
      EmbreeTracer tracer(scene.mesh, scene.objects);
      const EdgeDiffraction diffraction(scene.mesh, scene.objects);
      DirectSound d = blockedDirect();
      std::vector<uint32_t> used;
      diffraction.apply(tracer, kSource, ListenerSphere{kListener, 0.5f}, kC, Bands(0.f), d, {},
                        glm::vec3(1.f, 0.f, 0.f), &used);
      for (uint32_t e : used) CHECK(e < diffraction.edges().size());
      // Heard from beside the doorway, close behind the wall: there the path is the straight
      // channel along the leaf's latch face, its exit clearing the stop's corner, which an
      // object's straight channels carry as the mesh leaf's do (before: nothing, -300 dB). The
      // two may differ in which channel owns the slit (the reveal's or the leaf's face's,
      // markSlitOwners): up to 2.8 dB found, 3 dB allowed.
      for (float z : {1.5f, 3.4f, 4.5f}) {
        const glm::vec3 beside{6.5f, 1.f, z};
        const Bands o = decibels(directLevel(scene, kSource, beside));
        const Bands m = decibels(directLevel(stoppedLeafScene(kWall, gap, kThickness, x0, side,
                                                              kLip), kSource, beside));
        for (int b = 0; b < kNumBands; ++b) {
          INFO(label << ", beside the doorway at z " << z << ", band " << b);
          CHECK(std::abs(o[b] - m[b]) < 3.f);
        }
      }
    }
}

TEST_CASE("Door gaps: a leaf with a door stop swung open is never louder than the doorway",
          "[diffraction][door]") {
  // A box leaf against a stop (in the mesh or a moving object) swung 20 and 45 degrees into the
  // source's room: the line of sight crosses the leaf, and the paths round its free edge
  // (chains) are at most the doorway with its stop and without the leaf, as heldBound holds
  // that doorway (its small surfaces' bound: the stop's strips). Before, the chains were held
  // at the doorway's raw sum only, and read 4 to 6.4 dB above it at 63 Hz.
  constexpr float kThickness = 0.04f, kWall = 0.2f, kLip = 0.02f, kGap = 0.005f;
  for (float side : {1.f, -1.f}) {
    const float x0 = side > 0.f ? 6.01f : 6.f + kWall - 0.01f - kThickness;
    SceneDesc doorway = thickDoorwayScene(kWall, false);
    addDoorStop(doorway.mesh, kGap, kThickness, x0, side, kLip);
    const Bands open = decibels(directLevel(doorway));
    for (float degrees : {20.f, 45.f}) {
      SceneDesc shut = objectLeafScene(kWall, kGap, kThickness, x0 + 0.5f * kThickness);
      addDoorStop(shut.mesh, kGap, kThickness, x0, side, kLip);
      const SceneDesc scene = swungAwayFromStop(shut, side, degrees);
      const Bands object = decibels(directLevel(scene));
      const Bands fixed = decibels(directLevel(objectsInMesh(scene)));
      char label[96];
      std::snprintf(label, sizeof label,
                    "leaf with stop %s, ajar %2.0f deg: object / in the mesh / doorway (dB)",
                    side > 0.f ? "behind" : "before", double(degrees));
      printLevels(label, {&object, &fixed, &open});
      for (int b = 0; b < kNumBands; ++b) {
        INFO("stop side " << side << ", " << degrees << " degrees, band " << b);
        CHECK(object[b] <= open[b] + 0.05f);
        CHECK(fixed[b] <= open[b] + 0.05f);
      }
    }
  }
}

TEST_CASE("Door gaps: a box leaf in a thick wall heard from above the lintel's height",
          "[diffraction][door]") {
  // The listener 1.5 m behind a closed box leaf (4 cm, 10 mm gaps, in the middle of a 0.2 m
  // wall) rises from 1.8 to 2.9 m: the side gaps' points of least path length climb past the
  // leaf's top and the lintel hides them, yet the rest of each 2 m slit still sees the listener.
  // Before, every point from 2.55 m up heard nothing at all; now the channel is taken through
  // the visible part of its slit (engine/channel_path.h, visibleChannel). Checked: something
  // passes at every point, never more than the open doorway. The level falls smoothly but for
  // the step where the top gap's back leg meets the lintel (2.5-4.6 dB at 63-500 Hz between
  // 2.45 and 2.50 m: the slit's radiation round the lintel's edge is a second-order path dpc
  // does not have) and a rise of 2.1-3.7 dB between 2.54 and 2.56 m, where the open doorway
  // rises by 2 dB too (the top slit, carried by the lintel's reveal, is no longer taken down
  // by the held sum without the wall's face; printed, docs/validation.md).
  const SceneDesc closedScene = recessedLeafScene(0.2f, 0.01f, 0.04f, 6.1f);
  const SceneDesc openScene = thickDoorwayScene(0.2f, false);
  for (float y = 1.8f; y <= 2.901f; y += 0.05f) {
    const glm::vec3 listener{7.5f, y, 2.5f};
    const Bands closed = decibels(directLevel(closedScene, kSource, listener));
    const Bands open = decibels(directLevel(openScene, kSource, listener));
    std::printf("box leaf, listener height %.2f m: closed re free field (dB)", double(y));
    for (int b = 0; b < kNumBands; ++b) std::printf(" %5.1f", double(closed[b]));
    std::printf("\n");
    for (int b = 0; b < kNumBands; ++b) {
      INFO("listener height " << y << ", band " << b);
      CHECK(closed[b] > -60.f);
      CHECK(closed[b] <= open[b]);
    }
  }
}
