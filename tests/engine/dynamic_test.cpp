// Dynamic scenes in the engine: sources that move, objects that move (Embree instances), and
// the τ = 0 equality of a moved object with the same object baked into the static mesh.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <glm/gtc/quaternion.hpp>
#include <span>
#include <vector>

#include "engine/embree_tracer.h"
#include "engine/simulation.h"
#include "scene/trajectory.h"
#include "testing/test_scenes.h"
#include "testing/test_util.h"

using namespace dpc;

namespace {

/// One frame of `sim` with its first listener at `listener` (the scene's sources) and the
/// scene's objects at `poses`.
void runWithPoses(Simulation& sim, const glm::vec3& listener, const std::vector<Pose>& poses) {
  FrameInputs in = sim.inputsAt(listener);
  in.objectPoses = poses;
  sim.runFrame(in);
}

constexpr double kPi = 3.14159265358979323846;

}  // namespace

TEST_CASE("A source moving in a free field: delay r/c and energy 1/(4 pi r^2) every frame",
          "[dynamic]") {
  // "Free field": one fully absorbing floor far below (the mesh must not be empty).
  SceneDesc s;
  s.path = "<free field>";
  s.materials.push_back(Material{"absorber", Bands(1.f), Bands(0.f)});
  test::addPanel(s.mesh, {-100, -50, -100}, {200, 0, 0}, {0, 0, 200}, 0);
  SourceDesc src;
  src.name = "walker";
  Keyframe a, b;
  a.timeSeconds = 0.0, a.position = {1, 0, 0};
  b.timeSeconds = 4.0, b.position = {7, 0, 0};  // 1.5 m/s
  src.trajectory = {a, b};
  s.sources.push_back(src);
  s.listeners.emplace_back();
  s.listeners[0].radius = 0.25f;
  s.propagation.airAbsorption = false;
  // The floor's far rim would add a diffracted wave (about 1e-4 of the energy) to the direct
  // sound; this test checks the direct path alone.
  s.propagation.diffraction = false;
  s.propagation.raysPerFrame = 64;
  s.propagation.frameRate = 10.f;
  Simulation sim(s);
  const double c = s.propagation.speedOfSound;
  for (int f = 0; f <= 40; ++f) {
    const double t = f / 10.0;
    const glm::vec3 p = sourcePositionAt(s.sources[0], t);
    sim.runFrame(glm::vec3(0.f), {p});
    const DirectSound& d = sim.result(0).direct;
    const double r = 1.0 + 1.5 * t;
    REQUIRE(d.visible);
    // Float rounding of positions and of 1/(4 pi r^2): relative 1e-5.
    CHECK(d.distance == Approx(r).epsilon(1e-5));
    CHECK(d.delaySeconds == Approx(r / c).epsilon(1e-5));
    for (int band = 0; band < kNumBands; ++band)
      CHECK(d.intensity[band] == Approx(1.0 / (4.0 * kPi * r * r)).epsilon(1e-5));
  }
}

TEST_CASE("An object moved to a pose equals the static scene with it baked in (tau = 0)",
          "[dynamic]") {
  const glm::vec3 size{8, 4, 6};
  SceneDesc moving =
      test::makeShoebox(size, Bands(0.2f), 0.5f, {1.5f, 1.5f, 1.5f}, {6.f, 2.f, 4.f}, 0.5f);
  moving.materials.push_back(Material{"door", Bands(0.9f), Bands(0.1f)});  // an absorbing panel
  moving.propagation.estimator = Estimator::kPathTracing;
  moving.propagation.cacheTau = 0.f;
  moving.propagation.raysPerFrame = 4096;
  moving.propagation.maxOrder = 30;
  moving.propagation.rouletteThreshold = 0.f;
  // A 2 m x 3 m panel in local coordinates, placed by a pose: 30 degrees about +y, moved.
  ObjectDesc door;
  door.name = "door";
  test::addPanel(door.mesh, {0, 0, 0}, {2, 0, 0}, {0, 3, 0}, 1);
  ObjectKeyframe key;
  key.position = {3.5f, 0.5f, 2.5f};
  key.rotation = glm::angleAxis(float(kPi / 6), glm::vec3(0, 1, 0));
  door.trajectory = {key};
  // The same panel baked into the static mesh at that pose.
  SceneDesc baked = moving;
  for (glm::vec3 v : door.mesh.vertices)
    baked.mesh.vertices.push_back(key.rotation * v + key.position);
  const auto base = uint32_t(moving.mesh.vertices.size());
  for (size_t t = 0; t < door.mesh.triangles.size(); ++t) {
    const auto& tri = door.mesh.triangles[t];
    baked.mesh.triangles.push_back({base + tri[0], base + tri[1], base + tri[2]});
    baked.mesh.materialIndex.push_back(1);
  }
  // Start the moving one elsewhere, then move it to the pose.
  ObjectKeyframe away = key;
  away.position = {20.f, 0.f, 0.f};  // outside the room: no effect
  door.trajectory = {away};
  moving.objects.push_back(door);

  Simulation a(moving), b(baked);
  runWithPoses(a, moving.listeners[0].position, {Pose{key.position, key.rotation}});
  b.runFrame(baked.listeners[0].position);
  // Same rays (same seed), same surfaces; but the instance transform rounds differently from
  // the baked vertices, so a ray grazing an edge takes another branch and from there on is an
  // independent sample (diffuse reflections amplify any difference). So: equal within Monte
  // Carlo error, not float rounding. The error bar is measured: the spread of one frame's
  // total over 8 independent frames (other frame indices: other streams) of the baked scene;
  // the two estimates must agree within 3 standard errors of a difference of two independent
  // frames (sqrt 2 sigma), a bound they would meet even if no ray were shared.
  const Bands ea = a.result(0).energy.total(), eb = b.result(0).energy.total();
  double sum = 0.0, sum2 = 0.0;
  const int n = 8;
  for (int f = 0; f < n; ++f) {
    b.runFrame(baked.listeners[0].position);
    const double e = b.result(0).energy.total()[3];
    sum += e, sum2 += e * e;
  }
  const double mean = sum / n,
               sigma = std::sqrt(std::max(0.0, sum2 / n - mean * mean) * n / (n - 1));
  INFO("band 3 (500 Hz): moved " << ea[3] << ", baked " << eb[3] << ", sigma " << sigma);
  CHECK(std::abs(double(ea[3]) - eb[3]) < 3.0 * std::sqrt(2.0) * sigma);
  for (int band = 0; band < kNumBands; ++band)
    CHECK(std::abs(double(ea[band]) - eb[band]) < 3.0 * std::sqrt(2.0) * sigma * eb[band] / eb[3]);
  // The panel really is there: left where it started, the response differs.
  Simulation c(moving);
  c.runFrame(moving.listeners[0].position);
  const Bands ec = c.result(0).energy.total();
  INFO("left at its start: " << ec[3]);
  CHECK(std::abs(double(ec[3]) - mean) > 3.0 * std::sqrt(2.0) * sigma);
}

TEST_CASE("An object between source and listener occludes the direct sound", "[dynamic]") {
  // A 2 m square screen (a moving object) across the line of sight, 3 m from each end: what
  // passes is the way round its four edges (engine/object_edges.h), each path 0.33 m longer
  // than the line of sight, a Fresnel number N = 2 delta / lambda of 1.9 at 1 kHz (13-16 dB
  // for one edge by Maekawa and ISO 9613-2). On the axis the four arrive in phase (the bright
  // spot behind a symmetric obstacle: -4 dB for four such edges), so 3 to 6 dB down.
  // Slid off the line of sight: the free field. Turned back across: down again.
  SceneDesc s = test::makeShoebox({10, 4, 4}, Bands(0.3f), 0.5f, {2, 2, 2}, {8, 2, 2}, 0.3f);
  s.propagation.raysPerFrame = 16;
  ObjectDesc wall;
  wall.name = "screen";
  test::addPanel(wall.mesh, {0, -1, -1}, {0, 2, 0}, {0, 0, 2},
                 0);  // 2 m x 2 m in the local y-z plane
  ObjectKeyframe k;
  k.position = {5, 2, 2};
  wall.trajectory = {k};
  s.objects.push_back(wall);
  Simulation sim(s);
  const double free = 1.0 / (4.0 * kPi * 36.0);  // 1/m^2 at 6 m; air takes under 0.1 dB
  const auto level = [&] {
    return 10.0 * std::log10(double(sim.result(0).direct.intensity[4]) / free);
  };
  sim.runFrame(s.listeners[0].position);
  CHECK((level() < -3.0 && level() > -6.0));
  // Slid sideways (z in [2.5, 4.5]): the line of sight at z = 2 is free.
  runWithPoses(sim, s.listeners[0].position, {Pose{{5, 2, 3.5f}, glm::quat(1, 0, 0, 0)}});
  CHECK(sim.result(0).direct.visible);
  CHECK(level() > -0.5);
  // Turned back across by 90 degrees about +x about its new centre: (y, z) -> (-z, y) keeps it
  // square, so it must block again once returned to z = 2.
  runWithPoses(sim, s.listeners[0].position,
               {Pose{{5, 2, 2}, glm::angleAxis(float(kPi / 2), glm::vec3(1, 0, 0))}});
  CHECK((level() < -3.0 && level() > -6.0));
}

TEST_CASE("A moving object's diffracting edges follow its pose", "[dynamic]") {
  // A 0.6 m crate starts beside the line of sight and is moved across it: the direct sound then
  // is what passes round the crate's edges at its new pose, the same as a simulation built
  // with the crate there from the start (bit for bit: the same geometry).
  SceneDesc s = test::makeShoebox({10, 4, 4}, Bands(0.3f), 0.5f, {2, 2, 2}, {8, 2, 2}, 0.3f);
  s.propagation.raysPerFrame = 16;
  ObjectDesc crate;
  crate.name = "crate";
  test::addSolidBox(crate.mesh, {-0.3f, -2.f, -0.3f}, {0.3f, 2.f, 0.3f}, 0);
  crate.trajectory = {ObjectKeyframe{0.0, glm::vec3(5.f, 2.f, 3.5f), glm::quat(1, 0, 0, 0)}};
  s.objects.push_back(crate);
  Simulation moved(s);
  moved.runFrame(s.listeners[0].position);
  const Pose across{{5.f, 2.f, 2.f}, glm::quat(1, 0, 0, 0)};
  runWithPoses(moved, s.listeners[0].position, {across});
  s.objects[0].trajectory[0].position = across.position;
  Simulation there(s);
  there.runFrame(s.listeners[0].position);
  const Bands a = moved.result(0).direct.intensity, b = there.result(0).direct.intensity;
  for (int band = 0; band < kNumBands; ++band) {
    CHECK(a[band] == b[band]);
    CHECK(a[band] > 0.f);
  }
}

TEST_CASE("A door closing and opening is answered within tau by the window estimator",
          "[dynamic][response][statistics]") {
  const float tau = 0.5f;
  SceneDesc s = test::twoRooms(DpcWeighting::kWindow, tau);
  Simulation sim(s);
  const glm::vec3 L = s.listeners[0].position;
  const int W = int(std::lround(tau * s.propagation.frameRate));  // frames in tau
  auto late = [&] { return double(sim.result(0).energy.total()[3]); };
  std::vector<Pose> door = {test::kDoorOpen};
  const auto frame = [&] { runWithPoses(sim, L, door); };

  // Open: settle for 2 tau, then the reference level is the mean of 4 tau of readouts
  // (each the mean of W independent frames; the reference's own error is 1/sqrt(4) of that).
  for (int f = 0; f < 2 * W; ++f) frame();
  double open = 0.0;
  for (int f = 0; f < 4 * W; ++f) frame(), open += late();
  open /= 4 * W;
  REQUIRE(open > 0.0);
  // No line of sight through the doorway: what direct sound there is goes through it round the
  // jamb and on round the open door's free edge (a chain over a static and a moving edge 1.06 m
  // apart), well under the free field.
  CHECK_FALSE(lineOfSight(EmbreeTracer(s.mesh, {}), s.sources[0].position, L));
  const float d = glm::distance(s.sources[0].position, L);
  CHECK(sim.result(0).direct.intensity.max() < float(0.5 / (4.0 * kPi * d * d)));

  // Shut: only the 1 cm slit round the door joins the rooms, so the settled level is near 0
  // (well under 1 % of the open level here); the readout must have
  // dropped by >= 90 % at the last frame within tau of the change (W - 1 frame periods later).
  door = {test::kDoorShut};
  std::vector<double> closing;
  for (int f = 0; f < W; ++f) frame(), closing.push_back(late());
  INFO("open level " << open << ", after shutting " << closing.front() << " .. " << closing.back());
  CHECK(closing.back() <= 0.1 * open);

  // Open again: >= 90 % restored within tau. The readout at W - 1 is a mean of W frames whose
  // relative standard error (measured below over the settled open frames) must leave room:
  // we require it at the 90 % line minus 3 standard errors of the readout would fail, so the
  // test asserts readout >= 0.9 * open and separately that the error is below 3 %.
  door = {test::kDoorOpen};
  std::vector<double> opening;
  for (int f = 0; f < W; ++f) frame(), opening.push_back(late());
  INFO("after opening " << opening.front() << " .. " << opening.back());
  CHECK(opening.back() >= 0.9 * open);
  double sum = 0.0, sum2 = 0.0;
  const int n = 4 * W;
  for (int f = 0; f < n; ++f) {
    frame();
    sum += late(), sum2 += late() * late();
  }
  const double mean = sum / n, sd = std::sqrt(std::max(0.0, sum2 / n - mean * mean));
  INFO("settled open readout: mean " << mean << ", sd " << sd);
  CHECK(sd < 0.033 * mean);  // 0.9 is 3 standard deviations below the mean: the check is sound
  CHECK(mean == Approx(open).epsilon(0.05));  // unbiased: the same level as before
}

TEST_CASE("The EMA tuned to tau answers slower than tau (what the window fixes)",
          "[dynamic][response]") {
  // Documents the difference measured in docs/dynamic.md: the EMA's readout 1 - exp(-t/tau)
  // is only 1 - exp(-(W-1)/W) ~ 55 % of the way after W - 1 frames, so it cannot meet the 90 %
  // bound; it needs ~2.3 tau.
  const float tau = 0.5f;
  SceneDesc s = test::twoRooms(DpcWeighting::kEma, tau);
  s.propagation.raysPerFrame = 2048;
  Simulation sim(s);
  const glm::vec3 L = s.listeners[0].position;
  const int W = int(std::lround(tau * s.propagation.frameRate));
  for (int f = 0; f < 6 * W; ++f) runWithPoses(sim, L, {test::kDoorOpen});
  const double open = sim.result(0).energy.total()[3];
  for (int f = 0; f < W; ++f) runWithPoses(sim, L, {test::kDoorShut});
  CHECK(sim.result(0).energy.total()[3] > 0.3 * open);  // far from a 90 % drop
}

// The thesis defines the DPC at tau = 0 as plain path tracing: with exact early paths on, a
// door swinging, the source and the listener moving, every frame of 30 must match bit for bit,
// from the sources and from the listeners (the exact paths' cache keeps nothing across frames
// in either: Simulation::exactPathRetention).
TEST_CASE("tau = 0 is plain path tracing bit for bit with source, object and listener moving",
          "[dynamic]") {
  for (const Tracing tracing : {Tracing::kFromSources, Tracing::kFromListeners})
    for (DpcWeighting w : {DpcWeighting::kWindow, DpcWeighting::kEma, DpcWeighting::kSeed}) {
      SceneDesc dpc = test::twoRooms(w, 0.f);
      dpc.propagation.raysPerFrame = 512;
      dpc.propagation.exactOrder = 3;
      dpc.propagation.tracing = tracing;
      SceneDesc pt = dpc;
      pt.propagation.estimator = Estimator::kPathTracing;
      pt.propagation.cacheTau = 1.f;  // the path tracer's own tau must not matter
      Simulation a(dpc), b(pt);
      for (int f = 0; f < 30; ++f) {
        const float u = float(f % 10) / 9.f;
        const Pose door{test::kDoorShut.position,
                        glm::slerp(test::kDoorShut.rotation, test::kDoorOpen.rotation, u)};
        const glm::vec3 src{2.f + u, 1.2f, 1.f}, lis{8.f - u, 1.2f, 1.f + u};
        FrameInputs in = a.inputsAt(lis, {src});
        in.objectPoses = {door};
        a.runFrame(in);
        b.runFrame(in);
        INFO("frame " << f);
        CHECK(test::identical(a.result(0).energy, b.result(0).energy));
        CHECK(a.specularPaths(0).size() == b.specularPaths(0).size());
      }
    }
}

TEST_CASE("Several listeners in one pass: each equals its own trace, Embree work is shared",
          "[dynamic][listeners]") {
  // The door scene with the door open; listeners: A (the scene's, room B), a second sphere at A,
  // and C in room A next to the source. The rays' random streams depend on (seed, frame,
  // source, ray) only, and each listener's hits reach its groups in ray order, so a listener
  // traced with others gets exactly the float operations of tracing it alone: the energy
  // responses are bit-identical (memcmp), for path tracing and for the DPC (window weighting,
  // whose entries live in insertion order: the listener index in the keys changes nothing
  // else).
  for (Estimator est : {Estimator::kPathTracing, Estimator::kDpc}) {
    SceneDesc sc = test::twoRooms(DpcWeighting::kWindow, 0.5f);
    sc.propagation.estimator = est;
    sc.propagation.raysPerFrame = 1024;
    const ListenerSphere a{sc.listeners[0].position, sc.listeners[0].radius};
    const ListenerSphere c{{3.5f, 1.2f, 2.f}, 0.4f};
    const std::vector<ListenerSphere> together = {a, a, c};
    Simulation multi(sc), aloneA(sc), aloneC(sc);
    const std::vector<glm::vec3> sources = {sc.sources[0].position};
    const auto withDoorOpen = [&](std::span<const ListenerSphere> listeners) {
      FrameInputs in = Simulation::inputsAt(listeners, sources);
      in.objectPoses = {test::kDoorOpen};
      return in;
    };
    for (int f = 0; f < 6; ++f) {
      multi.runFrame(withDoorOpen(together));
      aloneA.runFrame(withDoorOpen(std::span(&a, 1)));
      aloneC.runFrame(withDoorOpen(std::span(&c, 1)));
      REQUIRE(multi.listenerCount() == 3);
      const auto same = [](const EnergyResponse& x, const EnergyResponse& y) {
        return x.binCount() == y.binCount() &&
               std::memcmp(x.bins().data(), y.bins().data(), x.binCount() * sizeof(Bands)) == 0;
      };
      CHECK(multi.result(0, 0).energy.total()[3] > 0.f);
      CHECK(same(multi.result(0, 0).energy, aloneA.result(0).energy));
      CHECK(same(multi.result(0, 1).energy, aloneA.result(0).energy));
      CHECK(same(multi.result(0, 2).energy, aloneC.result(0).energy));
      CHECK(multi.result(0, 2).direct.visible);
      // One pass: the same Embree queries as one listener; the sphere tests add up.
      CHECK(multi.result(0, 0).trace.segments == aloneA.result(0).trace.segments);
      CHECK(multi.result(0, 0).trace.listenerHits ==
            2 * aloneA.result(0).trace.listenerHits + aloneC.result(0).trace.listenerHits);
    }
  }
}

TEST_CASE("Path identifiers carry the listener, segments do not grow with listeners",
          "[dynamic][listeners]") {
  SceneDesc sc = test::twoRooms(DpcWeighting::kWindow, 0.5f);
  sc.objects.clear();
  Geometry geometry(sc.mesh, sc.materials, sc.propagation.patchSize, sc.objects);
  EmbreeTracer tracer(sc.mesh, sc.objects);
  sc.propagation.raysPerFrame = 512;
  // No exact paths: the grouping overload leaves their hits out of the groups while
  // listenerHits counts every crossing, and this test counts one against the other.
  sc.propagation.exactOrder = 0;
  Propagator propagator(geometry, tracer, sc.propagation);
  const glm::vec3 source = sc.sources[0].position;
  uint64_t segmentsOne = 0;
  for (size_t n : {1, 2, 4, 8}) {
    // n listeners at the same place: identical groups, disjoint identifiers.
    std::vector<ListenerSphere> spheres(n, ListenerSphere{{3.f, 1.5f, 2.f}, 0.5f});
    std::vector<FrameGroups> groups(n);
    std::vector<FrameGroups*> ptrs;
    for (FrameGroups& g : groups) ptrs.push_back(&g);
    const TraceStats st =
        propagator.traceFrame(test::traceRequest(sc.propagation, 7, 0, source, spheres), ptrs);
    if (n == 1) segmentsOne = st.segments;
    CHECK(st.segments == segmentsOne);
    REQUIRE(groups[0].groups().size() > 10);
    CHECK(st.listenerHits == n * groups[0].hitCount());
    for (size_t l = 1; l < n; ++l) {
      REQUIRE(groups[l].groups().size() == groups[0].groups().size());
      for (size_t k = 0; k < groups[0].groups().size(); ++k) {
        const auto& g0 = groups[0].groups()[k];
        const auto& gl = groups[l].groups()[k];
        CHECK(gl.key != g0.key);
        CHECK(gl.eta == g0.eta);
        CHECK(gl.length == g0.length);
      }
    }
  }
}
