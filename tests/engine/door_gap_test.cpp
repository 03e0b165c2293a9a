// A door in a doorway between two rooms, source and listener on the line of sight through the
// doorway: closing it (gaps of 0, 5, 10 and 20 mm round the leaf) never makes the direct
// sound or the whole energy response louder than the open doorway, and what passes the gaps
// follows the slit model of engine/slit.h (Gomperts 1964; Mechel 1986), which
// tests/engine/slit_model.h computes on its own. Leaves set in thick walls and closing against
// a stop: door_frame_test.
#include <algorithm>
#include <array>
#include <catch2/catch.hpp>
#include <cmath>
#include <complex>
#include <cstdio>
#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>
#include <numbers>
#include <string>
#include <vector>

#include "engine/diffraction.h"
#include "engine/embree_tracer.h"
#include "engine/geometry.h"
#include "engine/propagation.h"
#include "engine/simulation.h"
#include "engine/surface_bound.h"
#include "scene/trajectory.h"
#include "testing/test_scenes.h"
#include "tests/engine/door_scenes.h"
#include "tests/engine/slit_model.h"

using namespace dpc;

using namespace dpc::door_test;

/// One row of the markdown table in docs/validation.md: gap, what, eight band levels (dB).
void tableRow(const char* gap, const char* what, const Bands& level) {
  std::printf("| %s | %s |", gap, what);
  for (int b = 0; b < kNumBands; ++b)
    std::printf(level[b] < -200.f ? " - |" : " %.1f |", double(level[b]));
  std::printf("\n");
}

TEST_CASE("Door gaps: closed is never louder than open, and the gaps pass what the slit model says",
          "[diffraction][door]") {
  // Prints docs/validation.md's table of the gaps (the lines beginning with "|").
  const MouthImpedance zr;
  const Bands open = decibels(directLevel(doorScene(0.f, Leaf::kNone)));
  std::printf(
      "| gap | direct re free field (dB) | 63 Hz | 125 | 250 | 500 | 1k | 2k | 4k | 8k |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|\n");
  tableRow("-", "open doorway (UTD)", open);
  for (float gap : {0.f, 0.005f, 0.01f, 0.02f}) {
    const Bands model = gap > 0.f ? modelLevels(perimeterSlits(gap), zr) : Bands(-300.f);
    const std::string mm = std::to_string(int(std::lround(gap * 1e3f))) + " mm";
    for (Leaf leaf : {Leaf::kStatic, Leaf::kObject}) {
      const Bands closed = decibels(directLevel(doorScene(gap, leaf)));
      tableRow(mm.c_str(),
               leaf == Leaf::kStatic ? "closed, leaf in the mesh" : "closed, leaf an object",
               closed);
      // Meshed with T-junctions, the jambs' edges run past the leaf; the slit along them ends
      // where the leaf does (engine/gap_probe.h): the same levels (found: within 0.05 dB;
      // allowed 0.2 dB, the probe's bisection of the slit's end to 4 mm). Taken as the edges'
      // whole length, the 20 mm slits read 1.2 dB more, above the open doorway at 63 Hz.
      const Bands tee = decibels(directLevel(doorScene(gap, leaf, 0.2f, true)));
      float teeWorst = 0.f;
      for (int b = 0; b < kNumBands && gap > 0.f; ++b) {
        CHECK(std::abs(tee[b] - closed[b]) < 0.2f);
        teeWorst = std::max(teeWorst, std::abs(tee[b] - closed[b]));
      }
      std::printf("T-junction mesh, %s: largest difference %.3f dB\n", mm.c_str(),
                  double(teeWorst));
      for (int b = 0; b < kNumBands; ++b) {
        // Closing the door adds no energy: below the open doorway and the free field.
        CHECK(closed[b] <= open[b]);
        CHECK(closed[b] <= 1e-4f);
        // The gap's level within 3 dB of the model per octave (dpc: the probed width, within
        // 5 % of the gap's, and the paraxial line integral; the model: the exact geometry).
        if (gap > 0.f) CHECK(std::abs(closed[b] - model[b]) < 3.0);
      }
    }
    if (gap > 0.f) tableRow(mm.c_str(), "slit model (this test)", model);
  }
}

TEST_CASE("Door gaps: a slatted screen never takes the direct sound away",
          "[diffraction][door][heavy]") {
  // A screen of slats 3 cm wide and 4 cm deep, 1.5 cm apart, 2 m tall, across the 12 x 3 x 5 m
  // room at x = 6 (no wall): a third of it open. Its slots' air is its only mass: the mass law of
  // a slotted panel, m' = rho d_eff / sigma (d_eff = 4 cm plus end corrections, under 6 cm; sigma
  // = 1/3), gives a transmission loss under 1 dB up to 250 Hz, so behind it the direct sound is
  // about the free field's there. The probe does not take the slots for slits (their mouths face
  // the source and the listener, not each other's edges), so the slats' edge paths carry it; the
  // paths whose legs thread a slot stay, as no slit carries that slot. Dropping them, as the
  // first version of the threaded-leg test did, left the direct sound out at 7 of 10 points of
  // such a walk (a held-out review's screen, 2 cm steps). The floor checked is 20 dB below the
  // free field from 63 to 250 Hz: the sum of the slats' first-order UTD fields scatters about
  // the mass law's level by -15.5 to +1.4 dB along this walk (before the small bodies were
  // bounded together, engine/small_bodies.h: to +12.0 dB; the low side, where a slat blocks the
  // line of sight, is still short: docs/validation.md), so only its loss is caught.
  SceneDesc s = doorScene(0.f, Leaf::kNone);
  s.mesh = test::makeShoebox({12, 3, 5}, Bands(0.2f), 0.3f, kSource, kListener, 0.5f).mesh;
  for (float z = 1.f; z + 0.03f <= 4.f; z += 0.045f)
    test::addSolidBox(s.mesh, {5.98f, 0.f, z}, {6.02f, 2.f, z + 0.03f}, 0);
  for (float z = 2.6f; z <= 3.001f; z += 0.02f) {
    const glm::vec3 listener{9.f, 1.2f, z};
    const Bands level = decibels(directLevel(s, kSource, listener));
    std::printf("slatted screen, listener z %.2f m: direct re free field (dB)", double(z));
    for (int b = 0; b < kNumBands; ++b) std::printf(" %5.1f", double(level[b]));
    std::printf("\n");
    for (int b = 0; b < kNumBands; ++b) {
      INFO("listener z " << z << ", band " << b);
      if (b < 3) CHECK(level[b] > -20.f);
      // Nor above the free field by more than the knife edge's lit-side ripple (+1.37 dB), in
      // any band: with the line of sight through a slot the slats' edge terms, in phase along
      // the row, give up to 3.4 and 12.5 dB above it at 4 and 8 kHz summed alone.
      CHECK(level[b] < 10.f * std::log10(kLitRipple) + 0.05f);
    }
  }
}

namespace {

/// The whole energy response at the listener per band (1/m^2): the estimator's bins plus the
/// direct sound, the mean of `frames` frames of a fixed seed.
Bands totalEnergy(const SceneDesc& scene, int frames) {
  Simulation sim(scene);
  Bands total(0.f);
  for (int f = 0; f < frames; ++f) {
    sim.runFrame(kListener);
    const auto& r = sim.result(0);
    for (const Bands& bin : r.energy.bins()) total += bin;
    total += r.direct.intensity;
  }
  return total * (1.f / float(frames));
}

}  // namespace

TEST_CASE("Door gaps: the whole energy response is never louder closed than open",
          "[diffraction][door]") {
  // Nearly anechoic rooms (absorption 0.9), so that the direct sound weighs in the total as
  // much as the reflections do. The ray-traced part's Monte Carlo error (10 frames of 8192
  // rays: a few per cent) is far below the margins, so the comparison is strict.
  constexpr int kFrames = 10;
  constexpr float kAlpha = 0.9f;
  const Bands open = decibels(totalEnergy(doorScene(0.f, Leaf::kNone, kAlpha), kFrames));
  for (float gap : {0.f, 0.005f, 0.01f, 0.02f}) {
    const Bands closed = decibels(totalEnergy(doorScene(gap, Leaf::kObject, kAlpha), kFrames));
    std::printf("total, gap %2.0f mm: closed - open (dB)", double(gap) * 1e3);
    for (int b = 0; b < kNumBands; ++b) std::printf(" %6.1f", double(closed[b] - open[b]));
    std::printf("\n");
    for (int b = 0; b < kNumBands; ++b) CHECK(closed[b] <= open[b]);
  }
  // A real door: a 4 cm box leaf in the middle of a 0.2 m wall, its gaps passed as channels.
  const Bands thickOpen =
      decibels(totalEnergy(thickDoorwayScene(0.2f, false, kAlpha), kFrames));
  for (float gap : {0.f, 0.005f, 0.01f, 0.02f}) {
    const Bands closed =
        decibels(totalEnergy(recessedLeafScene(0.2f, gap, 0.04f, 6.1f, kAlpha), kFrames));
    std::printf("total, box leaf in a 0.2 m wall, gap %2.0f mm: closed - open (dB)",
                double(gap) * 1e3);
    for (int b = 0; b < kNumBands; ++b) std::printf(" %6.1f", double(closed[b] - thickOpen[b]));
    std::printf("\n");
    for (int b = 0; b < kNumBands; ++b) CHECK(closed[b] <= thickOpen[b]);
  }
}

TEST_CASE("Door gaps: scenes/two_rooms.json's talker is clearly quieter at b with the door shut",
          "[diffraction][door]") {
  // The talker in room A, listener b in room B without line of sight through the doorway;
  // the door (a leaf object with 1 cm gaps, transmitting) open at 2 s, shut at 7 s.
  const SceneDesc scene = loadScene(std::string(DPC_SOURCE_DIR) + "/scenes/two_rooms.json");
  Geometry geometry(scene.mesh, scene.materials, scene.propagation.patchSize, scene.objects);
  EmbreeTracer tracer(scene.mesh, scene.objects);
  EdgeDiffraction diffraction(scene.mesh, scene.objects);
  Propagator prop(geometry, tracer, scene.propagation);
  const SourceDesc& talker = scene.sources[0];
  const glm::vec3 forward = sourceForward(sourceRotationAt(talker, 0.0));
  const ListenerSphere b{scene.listeners[1].position, scene.listeners[1].radius};
  auto direct = [&](double t) {
    tracer.setObjectPose(0, objectPoseAt(scene.objects[0], t));
    tracer.commitPoses();
    diffraction.setObjectPoses({objectPoseAt(scene.objects[0], t)});
    DirectSound d = prop.directSound(talker.position, b, talker.directivity, forward);
    diffraction.apply(tracer, talker.position, b, scene.propagation.speedOfSound,
                      prop.airAttenuationPerMetre(), d, talker.directivity, forward);
    return decibels(d.intensity);
  };
  const Bands open = direct(2.0), shut = direct(7.0);
  std::printf("two_rooms talker -> b direct (dB re 1/m^2):\n  open");
  for (int b = 0; b < kNumBands; ++b) std::printf(" %6.1f", double(open[b]));
  std::printf("\n  shut");
  for (int b = 0; b < kNumBands; ++b) std::printf(" %6.1f", double(shut[b]));
  std::printf("\n");
  // "Clearly": at least 3 dB (twice the power) in every band. The gaps and the partition's
  // transmission keep it from more at 63 Hz (slit model: a 1 cm slit passes about 10 times
  // its area there) and at 8 kHz (the slits radiate into the jamb's shadow about as strongly
  // as the open doorway's edge diffracts into it).
  for (int b = 0; b < kNumBands; ++b) CHECK(shut[b] < open[b] - 3.f);
}

TEST_CASE("Door gaps: scenes/two_rooms.json's door ajar reads as the same leaf in the static mesh",
          "[diffraction][door]") {
  // The shipped scene's door (a leaf object, 1 cm gaps) swung 2-15 degrees into room B, the
  // talker in room A, listener b without line of sight through the doorway. The same leaf
  // written into the static mesh takes the paths of first-order edges (its free rim's gap to
  // the latch jamb probed as a slit); the object's rim was a chain of one edge with no gap
  // probed, a free edge's field: from 3 to 15 degrees the door read the open doorway at
  // 63 Hz, up to 7 dB above the mesh leaf (-8.5 against -14.7 dB at 6 degrees). Now the rim
  // whose gap the probe finds is that slit's edge path (engine/diffraction.cpp addObjectRims).
  // Same geometry, same model: within 0.5 dB (the object's edges are placed by its pose, the
  // mesh's welded and rounded to float once: found 0.1 dB at most). At 20 degrees the rim's
  // own probe finds no gap and the object still reads -8.5 against -14.7 dB (docs/validation.md).
  // And against the open doorway (the door taken out): ajar up to 10 degrees, its latch gap at
  // most 17 cm of the doorway's metre, at least 3 dB below it at 63-250 Hz (found 5.5-10 dB),
  // so a door the engine ignored, as an object and in the mesh alike, fails here.
  auto [scene, talker, b, open] = twoRoomsDoor();
  for (float degrees : {2.f, 4.f, 6.f, 8.f, 10.f, 15.f}) {
    turnDoor(scene, degrees);
    const Bands object = decibels(directLevel(scene, talker, b));
    const Bands mesh = decibels(directLevel(objectsInMesh(scene), talker, b));
    char label[80];
    std::snprintf(label, sizeof label,
                  "two_rooms door ajar %2.0f deg: object / in the mesh / open (dB)", double(degrees));
    printLevels(label, {&object, &mesh, &open}, 4);
    for (int band = 0; band <= 4; ++band) {  // 63 Hz - 1 kHz
      INFO(degrees << " degrees, band " << band);
      CHECK(std::abs(object[band] - mesh[band]) < 0.5f);
      if (degrees <= 10.f && band <= 2) CHECK(object[band] < open[band] - 3.f);
    }
  }
}

TEST_CASE("Door gaps: scenes/two_rooms.json's door opened 70-90 degrees takes little from the "
          "open doorway", "[diffraction][door]") {
  // The shipped door swung nearly open (its keyframes sweep 90 to 0 degrees), listener b behind
  // the leaf's plane from 70 to 85 degrees: every path turns round the hinge jamb and passes
  // the leaf by its 1 cm hinge gap (a slit) or round its free rim (a chain of two edges, the
  // jamb's leg along the leaf's face). Before, that chain was not laid (its leg lies in the
  // leaf's plane, the straight line past the rim threads the hinge gap, and the rim is a moving
  // object's), and the door read 10.3 dB below the open doorway at 63 Hz, 9-11 dB at 125 Hz-1
  // kHz. dpc-wave's FDTD of the same doorway and leaf (scripts/door_wave.py, "beside the
  // doorway": docs/data/door-wave.json) has the leaf take 1.1-2.6 dB at 63 Hz, up to 3.3 dB at
  // 125 Hz; an obstruction adds no more than a knife edge's lit-side ripple (kLitRipple,
  // 1.37 dB: the box leaf in the mesh at 90 degrees, b 0.3 m off its face). So at 63-250 Hz:
  // within 3 dB below the open doorway and at most the ripple above it, as an object and in the
  // static mesh, the shipped sheet and the 4 cm box leaf of scenes/door.obj (before: 2.7-3 dB
  // above the open doorway at 70-80 degrees in the mesh, 8.3 dB below it at 85 as an object).
  auto [scene, talker, b, open] = twoRoomsDoor();
  const float ripple = 10.f * std::log10(kLitRipple) + 0.05f;
  SceneDesc box = scene;
  box.objects[0].mesh = Mesh{};
  test::addSolidBox(box.objects[0].mesh, {-0.02f, 0.f, 0.01f}, {0.02f, 2.09f, 0.99f},
                    scene.objects[0].mesh.materialIndex[0]);
  for (SceneDesc* leaf : {&scene, &box})
    for (float degrees : {70.f, 75.f, 80.f, 85.f, 90.f}) {
      turnDoor(*leaf, degrees);
      const Bands object = decibels(directLevel(*leaf, talker, b));
      const Bands mesh = decibels(directLevel(objectsInMesh(*leaf), talker, b));
      char label[80];
      std::snprintf(label, sizeof label, "two_rooms %s door open %2.0f deg: object / mesh / open",
                    leaf == &box ? "box" : "sheet", double(degrees));
      printLevels(label, {&object, &mesh, &open}, 4);
      for (int band = 0; band <= 2; ++band) {  // 63-250 Hz
        INFO((leaf == &box ? "box, " : "sheet, ") << degrees << " degrees, band " << band);
        for (float level : {object[band], mesh[band]}) {
          CHECK(level > open[band] - 3.f);
          CHECK(level < open[band] + ripple);
        }
      }
    }
}

TEST_CASE("Door gaps: a sheet leaf that is a moving object, ajar, reads as the same leaf in the mesh",
          "[diffraction][door]") {
  // doorScene's sheet leaf (5 mm gaps, a thin partition) as a moving object swung 1-12 degrees
  // either way, on the axis. The object's rim is a chain of one edge; its leg to the source was
  // taken as threading a gap: the parallel segment 3 cm to one side met the wall's jamb, the one
  // on the other side started behind the leaf's own sheet. Before, ajar 2-5 degrees read about
  // 8 dB below shut (-20.3 against -12.6 dB at 63 Hz at 3 degrees; the leaf in the mesh -11.5).
  // The same geometry through the mesh's first-order paths: within 0.5 dB, and opening it never
  // takes it more than 0.5 dB below shut.
  const Bands shut = decibels(directLevel(doorScene(0.005f, Leaf::kObject)));
  for (float degrees : {1.f, 2.f, 3.f, 5.f, 8.f, 12.f})
    for (float way : {1.f, -1.f}) {
      SceneDesc scene = doorScene(0.005f, Leaf::kObject);
      scene.objects[0].trajectory[0].rotation =
          glm::angleAxis(glm::radians(way * degrees), glm::vec3(0, 1, 0));
      const Bands object = decibels(directLevel(scene));
      const Bands mesh = decibels(directLevel(objectsInMesh(scene)));
      char label[80];
      std::snprintf(label, sizeof label,
                    "sheet leaf ajar %+3.0f deg: object / in the mesh / shut (dB)",
                    double(way * degrees));
      printLevels(label, {&object, &mesh, &shut}, 4);
      for (int b = 0; b <= 4; ++b) {  // 63 Hz - 1 kHz
        INFO(way * degrees << " degrees, band " << b);
        CHECK(std::abs(object[b] - mesh[b]) < 0.5f);
        CHECK(object[b] > shut[b] - 0.5f);
      }
    }
}

TEST_CASE("Door gaps: a sliding door part-way across its doorway is never louder than it open",
          "[diffraction][door]") {
  // A sheet leaf (the doorway's size less 1 cm gaps) 2 cm in front of the wall, slid along it
  // 0.1-0.9 m (a barn door; as a moving object and as the same leaf in the static mesh). With
  // the line of sight free (from 0.5 m), the object's own edges have no first-order paths, so
  // the sum kept the doorway's far jamb and lintel but lost the near jamb the leaf hides and
  // the leaf's rim that stands for it: before, 4.9 dB above the open doorway at 63 Hz, 2.7 dB
  // at 125 Hz. An obstruction adds no energy: at most the open doorway times the knife edge's
  // lit-side ripple (kLitRipple, 1.37 dB), in every band. Slid 0.1 m, the leaf covers nine
  // tenths of the opening and the line of sight: at least 3 dB below it at 63 Hz-1 kHz (found
  // 3.6-19.7 dB), so a leaf the engine ignored fails here.
  const Bands open = decibels(directLevel(doorScene(0.01f, Leaf::kNone)));
  const float ripple = 10.f * std::log10(kLitRipple) + 0.05f;
  for (float slid : {0.1f, 0.3f, 0.5f, 0.7f, 0.9f}) {
    SceneDesc scene = doorScene(0.01f, Leaf::kObject);
    scene.objects[0].trajectory[0].position = glm::vec3(5.98f, 0.f, kDoorZ0 + 0.01f + slid);
    const Bands object = decibels(directLevel(scene));
    const Bands mesh = decibels(directLevel(objectsInMesh(scene)));
    char label[80];
    std::snprintf(label, sizeof label, "sliding door %.1f m open: object / in the mesh / open (dB)",
                  double(slid));
    printLevels(label, {&object, &mesh, &open});
    for (int b = 0; b < kNumBands; ++b) {
      INFO(slid << " m open, band " << b);
      CHECK(object[b] <= open[b] + ripple);
      CHECK(mesh[b] <= open[b] + ripple);
      if (slid < 0.2f && b <= 4) CHECK(object[b] < open[b] - 3.f);
    }
  }
}

TEST_CASE("Door gaps: an obstacle in a window never lifts the direct sound above the free field",
          "[diffraction][door]") {
  // A 1 m square window in a free-standing wall (four rims), a 10 cm plate in its middle (a
  // moving object, chains round its rims only) blocking the line of sight. The four rims see the listener
  // on their lit side; near their shadow boundaries each one's UTD field is about minus half
  // the incident one, which sum to more than the free field at low frequencies. With the line
  // of sight blocked the result is held at the free field.
  SceneDesc s;
  s.materials.push_back(Material{"wall", Bands(0.1f), Bands(0.f)});
  const glm::vec3 y{0, 1, 0}, z{0, 0, 1};
  test::addPanel(s.mesh, {6, -20, -20}, 40.f * z, 19.5f * y, 0);    // below the window
  test::addPanel(s.mesh, {6, 0.5f, -20}, 40.f * z, 19.5f * y, 0);   // above
  test::addPanel(s.mesh, {6, -0.5f, -20}, 19.5f * z, 1.f * y, 0);   // left
  test::addPanel(s.mesh, {6, -0.5f, 0.5f}, 19.5f * z, 1.f * y, 0);  // right
  ObjectDesc plate;
  plate.name = "plate";
  test::addPanel(plate.mesh, {0, -0.05f, -0.05f}, 0.1f * z, 0.1f * y, 0);
  plate.trajectory = {ObjectKeyframe{0.0, {6.f, 0.f, 0.f}, glm::quat(1, 0, 0, 0)}};
  s.objects.push_back(plate);
  EmbreeTracer tracer(s.mesh, s.objects);
  const EdgeDiffraction diffraction(s.mesh, s.objects);
  const glm::vec3 src{3.f, 0.f, 0.f}, lis{9.f, 0.f, 0.f};
  DirectSound d;  // blocked by the plate
  d.distance = 6.f;
  d.delaySeconds = 6.f / kC;
  d.direction = {-1.f, 0.f, 0.f};
  REQUIRE(tracer.occluded(TraceRay{src, {1.f, 0.f, 0.f}, 1e-3f, 6.f - 1e-3f}));
  // The window's four rims and the wall's far outer rims, 20 m away.
  REQUIRE(diffraction.apply(tracer, src, ListenerSphere{lis, 0.5f}, kC, Bands(0.f), d) >= 4);
  const Bands level = decibels(d.intensity * float(4 * kPi * 36.0));
  std::printf("window with a plate: direct re free field (dB)");
  for (int b = 0; b < kNumBands; ++b) std::printf(" %6.1f", double(level[b]));
  std::printf("\n");
  for (int b = 0; b < kNumBands; ++b) CHECK(level[b] <= 1e-4f);
}

TEST_CASE("Door gaps: a double door's leaves meeting on the line of sight pass their slits only",
          "[diffraction][door][heavy]") {
  // Two leaves meet in the doorway's middle, 5 or 10 mm apart, the line of sight through that
  // gap; 0 or 10 mm round them. The slit model's field (engine/slit.h) is driven by the
  // incident pressure at the slit's mouth, so it carries the direct sound through the gap:
  // kept beside it, the closed door read the free field (+9 dB above the open doorway at 63
  // Hz). And the lintel's point of least path lies above that gap, where its mouth looks open:
  // it counted as a free edge (3-7 dB above the model from 125 Hz). Tolerance as for the gaps
  // round one leaf: 3 dB per octave against the model. Closed <= open in every band: with 10
  // mm round the leaves the four slits, summed as independent (each loaded by its own
  // radiation only, not by its neighbours' half a metre away, a tenth of a wavelength), passed
  // 0.9 dB more than the open doorway at 63 Hz; loading each other (engine/slit.h,
  // mutualLoading; the model here likewise) they pass 0.7 dB less.
  const MouthImpedance zr;
  const Bands open = decibels(directLevel(doorScene(0.f, Leaf::kNone)));
  for (float gap : {0.f, 0.01f})
    for (float middle : {0.005f, 0.01f}) {
      std::vector<Slit> slits = perimeterSlits(gap);
      const double zc = kDoorZ0 + 0.5 * kDoorWidth;
      slits.push_back({{6, 0, zc}, {6, kDoorHeight - gap, zc}, middle});
      const Bands model = modelLevels(slits, zr);
      const Bands closed = decibels(directLevel(doubleDoorScene(gap, middle)));
      std::printf("double door, %2.0f mm round, %2.0f mm between: closed / model (dB)",
                  double(gap) * 1e3, double(middle) * 1e3);
      for (int b = 0; b < kNumBands; ++b)
        std::printf(" %5.1f/%5.1f", double(closed[b]), double(model[b]));
      std::printf("\n");
      for (int b = 0; b < kNumBands; ++b) {
        CHECK(closed[b] <= open[b]);
        CHECK(std::abs(closed[b] - model[b]) < 3.0);
      }
    }
  // Box leaves 4 cm thick in the middle of a 0.2 m wall: every gap a channel as deep as the
  // leaves (the model's slits 4 cm deep), the line of sight through the middle one.
  const Bands thickOpen = decibels(directLevel(thickDoorwayScene(0.2f, false)));
  for (float gap : {0.005f, 0.01f})
    for (float middle : {0.005f, 0.01f}) {
      std::vector<Slit> slits = perimeterSlits(gap, 6.1, 0.04);
      const double zc = kDoorZ0 + 0.5 * kDoorWidth;
      slits.push_back({{6.1, 0, zc}, {6.1, kDoorHeight - gap, zc}, middle, 0.04});
      const Bands model = modelLevels(slits, zr);
      const Bands closed = decibels(directLevel(doubleBoxDoorScene(0.2f, gap, middle, 0.04f, 6.1f)));
      std::printf("double box door in a 0.2 m wall, %2.0f mm round, %2.0f mm between: closed / "
                  "model (dB)", double(gap) * 1e3, double(middle) * 1e3);
      for (int b = 0; b < kNumBands; ++b)
        std::printf(" %5.1f/%5.1f", double(closed[b]), double(model[b]));
      std::printf("\n");
      for (int b = 0; b < kNumBands; ++b) {
        CHECK(closed[b] <= thickOpen[b]);
        CHECK(std::abs(closed[b] - model[b]) < 3.0);
      }
    }
}

TEST_CASE("Door gaps: a double door seen beside its leaves' gap or off the axis is never louder",
          "[diffraction][door]") {
  // Source and listener moved together beside the leaves' 5 mm gap (the line of sight through
  // a leaf), and a pair off the axis without a line of sight; 5, 10 and 20 mm round the
  // leaves. The top gap's stationary point on the leaf's top edge then lies 2.5 mm from the
  // leaf's end: judged by the 4 widths either side of it the slit was too short, its field a
  // free edge's, and the door read up to 5.6 dB (beside) and 7.5 dB (off the axis) above the
  // open doorway at 63 Hz. Along the walk beside the gap (1 cm steps) the 63-500 Hz levels
  // change by at most 1 dB per step (a wavelength is 0.7 m or more; found: 0.7 dB); before, 5.8
  // dB within 1 cm at 63 Hz. Off the axis with 20 mm round the leaves, 63 Hz reads 0.4 dB above
  // the open doorway: the top gap runs across the side gaps, and slits that are not parallel
  // are not coupled (engine/slit.h); allowed 0.5 dB there, a limit docs/validation.md lists.
  const std::vector<std::pair<glm::vec3, glm::vec3>> pairs = {
      {{3.f, 1.6f, 4.2f}, {9.f, 0.9f, 0.7f}},
      {{3.f, 1.2f, 2.505f}, {9.f, 1.2f, 2.505f}},
      {{3.f, 1.2f, 2.55f}, {9.f, 1.2f, 2.55f}}};
  for (float gap : {0.005f, 0.01f, 0.02f})
    for (const auto& [src, lis] : pairs) {
      const Bands open = decibels(directLevel(doorScene(0.f, Leaf::kNone), src, lis));
      const Bands closed = decibels(directLevel(doubleDoorScene(gap, 0.005f), src, lis));
      for (int b = 0; b < kNumBands; ++b) {
        INFO("gap " << gap << " m, listener z " << lis.z << ", band " << b);
        const bool uncoupled = gap >= 0.02f && lis.z < 1.f && b == 0;
        CHECK(closed[b] <= open[b] + (uncoupled ? 0.5f : 0.f));
      }
    }
  float worst = 0.f;
  Bands previous(0.f);
  for (int i = 0; i <= 10; ++i) {
    const float z = 2.45f + 0.01f * float(i);
    const Bands level =
        decibels(directLevel(doubleDoorScene(0.02f, 0.005f), {3.f, 1.2f, z}, {9.f, 1.2f, z}));
    for (int b = 0; b <= 3 && i > 0; ++b) {
      CHECK(std::abs(level[b] - previous[b]) < 1.f);
      worst = std::max(worst, std::abs(level[b] - previous[b]));
    }
    previous = level;
  }
  std::printf("double door walk beside its gap: largest step 63-500 Hz %.2f dB\n", double(worst));
}

TEST_CASE("Door gaps: seen from off the axis, the gaps pass what the slit model says",
          "[diffraction][door][heavy]") {
  // Source and listener beside the doorway (both past one jamb, at other heights): the top
  // gap's edges then end before their point of least path length, so no edge path passes it,
  // yet the slit, a line source along its extent, does (the model integrates along it). Those
  // slits are now found from the ends of the edges of the leaf and frame whose side gaps were
  // found (engine/diffraction.cpp, addEndSlits), their path expanded at the edge's end
  // (engine/slit.h). Before, dpc read up to 2.2 dB below the model at 63 and 125 Hz; now
  // within 0.7 dB. Tolerance 1.5 dB per octave, half the 3 dB:
  // dpc and the model share the physics and differ by the paraxial Fresnel integral and the
  // incident pressure the slits' loading takes (the model's: at the source's height).
  const MouthImpedance zr;
  for (float gap : {0.005f, 0.01f, 0.02f})
    for (const auto& [src, lis] : kOffAxisPairs) {
      const Bands closed = decibels(directLevel(doorScene(gap, Leaf::kStatic), src, lis));
      const Bands model = modelLevels(perimeterSlits(gap), zr, glm::dvec3(src), glm::dvec3(lis));
      std::printf("gap %2.0f mm, source z %.1f m, listener z %.1f m: dpc - model (dB)",
                  1e3 * double(gap), double(src.z), double(lis.z));
      for (int b = 0; b < kNumBands; ++b) {
        std::printf(" %5.2f", double(closed[b] - model[b]));
        INFO("gap " << gap << " m, source z " << src.z << ", band " << b);
        CHECK(std::abs(closed[b] - model[b]) < 1.5f);
      }
      std::printf("\n");
    }
}

TEST_CASE("Door gaps: a leaf tight in its frame passes its undercut, from beside the doorway too",
          "[diffraction][door]") {
  // A leaf flush with the jambs and the lintel, 10 mm above the floor: only the undercut
  // passes sound. From beside the doorway its edge ends before the point of least path length
  // and, no other gap being found, nothing passed at all (no direct row). The undercut's slit
  // is now found from its edge's end when the leaf blocks the line of sight (addEndSlits), its
  // path expanded at that end (engine/slit.h). Against the slit model computed here (in a
  // baffle, as dpc takes it): on the axis within 0.2 dB, beside it within 2.1 dB (the model's
  // exact path lengths against dpc's second-order expansion at the end). Tolerance: the
  // issue's 3 dB per octave.
  const MouthImpedance zr;
  SceneDesc s = doorScene(0.f, Leaf::kNone);
  const float under = 0.01f;
  test::addPanel(s.mesh, {6.f, under, kDoorZ0}, kDoorWidth * glm::vec3(0, 0, 1),
                 (kDoorHeight - under) * glm::vec3(0, 1, 0), 0);
  const std::vector<Slit> undercut = {
      {{6, under / 2, kDoorZ0}, {6, under / 2, kDoorZ0 + kDoorWidth}, under}};
  const std::vector<std::pair<glm::vec3, glm::vec3>> pairs = {
      {{3.f, 1.2f, 2.5f}, {9.f, 1.2f, 2.5f}},
      {{3.f, 1.2f, 4.2f}, {9.f, 1.5f, 4.6f}},
      {{4.f, 1.2f, 4.5f}, {8.f, 1.2f, 4.5f}}};
  for (const auto& [src, lis] : pairs) {
    const Bands closed = decibels(directLevel(s, src, lis));
    const Bands model = modelLevels(undercut, zr, glm::dvec3(src), glm::dvec3(lis));
    std::printf("undercut, listener z %.1f m: dpc - model (dB)", double(lis.z));
    for (int b = 0; b < kNumBands; ++b) {
      std::printf(" %5.2f", double(closed[b] - model[b]));
      INFO("listener z " << lis.z << ", band " << b);
      CHECK(std::abs(closed[b] - model[b]) < 3.f);
    }
    std::printf("\n");
  }
}

TEST_CASE("Door gaps: a line of sight grazing a gap's far side still passes the gap",
          "[diffraction][door]") {
  // A listener walked in 1 cm steps past the line along which the line of sight grazes the
  // leaf's side of its 20 mm hinge gap. There the probed width (the geometric mean of the
  // deltas that bracket it, within 5 %) fell 0.2 mm short of the gap, so the line of sight
  // counted as free beside the slit and the direct sound was kept whole beside the slit's
  // field: 6.5 dB above the open doorway at 63 Hz at one point. Closed <= open everywhere
  // (0.01 dB: single-precision geometry).
  const glm::vec3 source{4.5f, 1.5f, 1.0f};
  for (int i = 0; i <= 10; ++i) {
    const glm::vec3 listener{6.5f, 1.2f, 2.31f + 0.01f * float(i)};
    const Bands open = decibels(directLevel(doorScene(0.f, Leaf::kNone), source, listener));
    const Bands closed = decibels(directLevel(doorScene(0.02f, Leaf::kStatic), source, listener));
    for (int b = 0; b < kNumBands; ++b) {
      INFO("listener z " << listener.z << ", band " << b);
      CHECK(closed[b] <= open[b] + 0.01f);
    }
  }
}
