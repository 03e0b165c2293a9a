// Exact early specular paths (engine/specular_paths.h) against oracles written here:
// - the Allen-Berkley image lattice of a shoebox (J. B. Allen & D. A. Berkley, JASA 65, 1979),
//   written from its definition, not with the code under test: image (i, j, k, mirror flags)
//   at (2 i Lx +- xs, 2 j Ly +- ys, 2 k Lz +- zs), n = |2i - fx| + |2j - fy| + |2k - fz|
//   reflections, energy (1 - alpha)^n (1 - s)^n / (4 pi d^2) without air, arrival direction
//   toward the image;
// - each lattice path's polyline in the real room (the straight line to the image folded back
//   at every wall crossing) tested against an occluding panel by a plain segment-rectangle test;
// - the energy balance of docs/estimators.md: energy response without the exact paths' rays
//   plus the exact paths equals plain path tracing, within Monte Carlo error.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include "engine/simulation.h"
#include "testing/test_scenes.h"
#include "testing/test_util.h"

using namespace dpc;

namespace {

constexpr double kC = 343.0;

struct Image {
  int order = 0;
  glm::dvec3 position{0.0};
  double distance = 0.0;  ///< to the listener, metres
};

/// Every image of `src` in the box [0, room] with 1..maxOrder reflections, as seen from lis.
std::vector<Image> lattice(glm::dvec3 room, glm::dvec3 src, glm::dvec3 lis, int maxOrder) {
  std::vector<Image> out;
  for (int i = -maxOrder; i <= maxOrder; ++i)
    for (int j = -maxOrder; j <= maxOrder; ++j)
      for (int k = -maxOrder; k <= maxOrder; ++k)
        for (int m = 0; m < 8; ++m) {
          const int fx = m & 1, fy = (m >> 1) & 1, fz = (m >> 2) & 1;
          const int n = std::abs(2 * i - fx) + std::abs(2 * j - fy) + std::abs(2 * k - fz);
          if (n == 0 || n > maxOrder) continue;
          Image im;
          im.order = n;
          im.position = {2.0 * i * room.x + (fx ? -src.x : src.x),
                         2.0 * j * room.y + (fy ? -src.y : src.y),
                         2.0 * k * room.z + (fz ? -src.z : src.z)};
          im.distance = glm::length(im.position - lis);
          out.push_back(im);
        }
  return out;
}

/// Coordinate x of the unfolded space folded back into [0, L].
double fold(double x, double L) {
  double r = std::fmod(x, 2.0 * L);
  if (r < 0) r += 2.0 * L;
  return r > L ? 2.0 * L - r : r;
}

/// The real path of an image: listener, reflection points (wall crossings of the straight line
/// from the listener to the image, folded back into the room), source.
std::vector<glm::dvec3> foldedPath(glm::dvec3 room, glm::dvec3 lis, const Image& im) {
  std::vector<double> ts{0.0, 1.0};
  const glm::dvec3 d = im.position - lis;
  for (int a = 0; a < 3; ++a) {
    if (d[a] == 0.0) continue;
    for (int w = -10; w <= 10; ++w) {
      const double t = (w * room[a] - lis[a]) / d[a];
      if (t > 1e-12 && t < 1 - 1e-12) ts.push_back(t);
    }
  }
  std::sort(ts.begin(), ts.end());
  std::vector<glm::dvec3> pts;
  for (double t : ts) {
    const glm::dvec3 p = lis + t * d;
    pts.push_back({fold(p.x, room.x), fold(p.y, room.y), fold(p.z, room.z)});
  }
  return pts;
}

/// True when segment a-b crosses the rectangle o + u s + v t, s, t in [0, 1].
bool crossesRectangle(glm::dvec3 a, glm::dvec3 b, glm::dvec3 o, glm::dvec3 u, glm::dvec3 v) {
  const glm::dvec3 n = glm::cross(u, v);
  const double da = glm::dot(a - o, n), db = glm::dot(b - o, n);
  if (da * db >= 0) return false;
  const glm::dvec3 p = a + (da / (da - db)) * (b - a) - o;
  const double s = glm::dot(p, u) / glm::dot(u, u), t = glm::dot(p, v) / glm::dot(v, v);
  return s >= 0 && s <= 1 && t >= 0 && t <= 1;
}

/// The 10 x 3 x 7 m shoebox of scenes/shoebox.obj, absorption 0.1, plain path tracing, no air.
SceneDesc box(float scattering, glm::vec3 src, glm::vec3 lis, int exactOrder) {
  SceneDesc s = test::makeShoebox({10, 3, 7}, Bands(0.1f), scattering, src, lis, 0.5f);
  s.propagation.estimator = Estimator::kPathTracing;
  s.propagation.airAbsorption = false;
  s.propagation.speedOfSound = float(kC);
  s.propagation.raysPerFrame = 8192;
  s.propagation.maxOrder = 30;
  s.propagation.exactOrder = exactOrder;
  s.propagation.diffraction = false;
  return s;
}

const glm::dvec3 kRoom{10, 3, 7};
const glm::vec3 kSrc{2.1f, 1.4f, 2.3f}, kLis{7.3f, 1.7f, 4.9f};

/// Matches every lattice image to a path of equal order by delay (1e-6 s) and checks its
/// energy (1e-4 relative), direction and order; returns the number of images matched. Every
/// path must match an image (no extra paths).
int matchLattice(const std::vector<SpecularPath>& paths, const std::vector<Image>& images,
                 glm::dvec3 lis, double scattering, double alpha = 0.1) {
  std::vector<int> used(paths.size(), 0);
  int matched = 0;
  for (const Image& im : images) {
    const double delay = im.distance / kC;
    const double energy = std::pow((1 - alpha) * (1 - scattering), im.order) /
                          (4 * std::numbers::pi * im.distance * im.distance);
    for (size_t p = 0; p < paths.size(); ++p) {
      if (used[p] || int(paths[p].order) != im.order) continue;
      if (std::abs(paths[p].delaySeconds - delay) > 1e-6) continue;  // 0.34 mm of path
      // Two images may share a delay: the arrival direction (toward the image) tells them
      // apart; 1e-5 is float rounding of a unit vector built from metre coordinates.
      const glm::dvec3 dir = glm::normalize(im.position - lis);
      if (glm::length(glm::dvec3(paths[p].direction) - dir) > 1e-5) continue;
      used[p] = 1;
      ++matched;
      for (int b = 0; b < kNumBands; ++b)
        CHECK(std::abs(paths[p].intensity[b] / energy - 1) < 1e-4);  // float rounding
      break;
    }
  }
  for (size_t p = 0; p < paths.size(); ++p) {
    INFO("path " << p << " order " << paths[p].order << " delay " << paths[p].delaySeconds);
    CHECK(used[p]);
  }
  return matched;
}

/// Runs `frames` frames at the scene's source and listener; returns the last frame's paths.
std::vector<SpecularPath> run(Simulation& sim, glm::vec3 lis, glm::vec3 src, int frames,
                              const std::vector<Pose>& objects = {}) {
  FrameInputs in = sim.inputsAt(lis, {src});
  in.objectPoses = objects;
  for (int f = 0; f < frames; ++f) sim.runFrame(in);
  return sim.specularPaths(0, 0);
}

}  // namespace

TEST_CASE("Specular shoebox: every image source up to order 3, exactly, and nothing else",
          "[specular]") {
  Simulation sim(box(0.f, kSrc, kLis, 3));
  const std::vector<SpecularPath> paths = run(sim, kLis, kSrc, 4);
  const std::vector<Image> images = lattice(kRoom, kSrc, kLis, 3);
  REQUIRE(images.size() == 62);  // 4 n^2 + 2 images of order n: 6 + 18 + 38
  std::printf("shoebox s=0: %zu exact paths, lattice %zu, candidates %zu, cached %zu\n",
              paths.size(), images.size(), sim.result(0).specularCandidates,
              sim.result(0).specularCacheEntries);
  CHECK(matchLattice(paths, images, kLis, 0.0) == 62);
  CHECK(paths.size() == 62);
  for (const SpecularPath& p : paths) CHECK(p.order <= 3);  // no order-4 path with N = 3
  // The same room with N = 4 adds exactly the 66 order-4 images: N is what limits the order.
  Simulation four(box(0.f, kSrc, kLis, 4));
  const std::vector<SpecularPath> paths4 = run(four, kLis, kSrc, 6);
  std::printf("shoebox s=0, N=4: %zu exact paths (lattice 128)\n", paths4.size());
  CHECK(matchLattice(paths4, lattice(kRoom, kSrc, kLis, 4), kLis, 0.0) == 128);
}

namespace {

/// A square panel, 0.3 m wide, across the floor's first-order path halfway between its
/// reflection point and the source, facing along the path: corner o, edges u and v.
struct Panel {
  glm::dvec3 centre, u, v;
  glm::dvec3 corner() const { return centre - 0.5 * u - 0.5 * v; }
};

Panel panelOnFloorPath() {
  const Image floor{1, {kSrc.x, -kSrc.y, kSrc.z}, 0.0};
  const std::vector<glm::dvec3> p = foldedPath(kRoom, kLis, floor);
  REQUIRE(p.size() == 3);
  const glm::dvec3 d = glm::normalize(p[2] - p[1]);
  Panel panel;
  panel.centre = p[1] + 0.5 * (p[2] - p[1]);
  panel.u = 0.3 * glm::normalize(glm::cross(d, glm::dvec3(0.3, 1, 0.2)));
  panel.v = 0.3 * glm::normalize(glm::cross(d, panel.u));
  return panel;
}

/// The lattice images whose folded paths the panel (at `shift` from its place) does not cross.
std::vector<Image> unblocked(const std::vector<Image>& images, const Panel& panel,
                             glm::dvec3 shift = glm::dvec3(0.0)) {
  std::vector<Image> open;
  for (const Image& im : images) {
    const std::vector<glm::dvec3> pts = foldedPath(kRoom, kLis, im);
    bool hit = false;
    for (size_t i = 0; i + 1 < pts.size(); ++i)
      hit = hit || crossesRectangle(pts[i], pts[i + 1], panel.corner() + shift, panel.u, panel.v);
    if (!hit) open.push_back(im);
  }
  return open;
}

}  // namespace

namespace {

/// The hits (all bands, 1/m^2) left in the response before the box's first order-4 arrival and
/// the exact paths' energy there, after one frame of the corner test below; `tilt` raises the
/// ceiling's far edge (z = 7 m) by that many metres, the corners along it no longer square.
std::pair<double, double> leftBeforeFourth(float tilt) {
  const glm::vec3 src{2.55f, 1.453f, 4.05f}, lis{6.583f, 1.673f, 3.283f};
  SceneDesc scene = box(0.f, src, lis, 3);
  for (glm::vec3& v : scene.mesh.vertices)
    if (v.y > 2.5f && v.z > 6.5f) v.y += tilt;
  scene.propagation.raysPerFrame = 20000;
  Simulation sim(scene);
  const std::vector<SpecularPath> paths = run(sim, lis, src, 1);
  double firstFourth = 1e9;  // the earliest order-4 arrival of the square box, s
  for (const Image& im : lattice(kRoom, glm::dvec3(src), glm::dvec3(lis), 4))
    if (im.order == 4) firstFourth = std::min(firstFourth, im.distance / kC);
  const EnergyResponse& er = sim.result(0).energy;
  EnergyResponse exact(er.binCount() * er.binSeconds(), er.binSeconds());
  addSpecularPaths(paths, exact);
  const auto last = size_t(firstFourth / er.binSeconds()) - 1;  // bins wholly before it
  double left = 0, replaced = 0;
  for (size_t k = 0; k < last; ++k)
    for (int b = 0; b < kNumBands; ++b) {
      left += er.bins()[k][b];
      replaced += exact.bins()[k][b];
    }
  std::printf("corner orders, ceiling raised %.0f mm at its far edge: hits left before %.1f ms "
              "%.3e of the exact paths' %.3e\n",
              1e3 * double(tilt), 1e3 * firstFourth, left, replaced);
  return {left, replaced};
}

}  // namespace

TEST_CASE("Specular shoebox: the orders round a corner are one arrival, all of its hits replaced",
          "[specular]") {
  // Floor then wall and wall then floor mirror the source to one image (two perpendicular
  // planes' reflections commute), and so do the six orders of three perpendicular planes. The
  // exact path is validated for the listener's centre, where one order is valid, but rays reach
  // the 0.5 m sphere by the others too where the corner's two validity regions meet inside it.
  // Scattering 0: every ray is specular, so every hit before the first order-4 arrival samples
  // an order <= 3 image, whose exact path replaces it; the hits left there must be none
  // (rounding aside), in this room 2.6 % of that window otherwise. The same with the ceiling
  // tilted 0.1 degrees (12 mm over 7 m), as a hand-made or surveyed room is built: the orders
  // round its corners mirror the source to points a centimetre apart, one arrival still.
  for (float tilt : {0.f, 0.0122f}) {
    const auto [left, replaced] = leftBeforeFourth(tilt);
    REQUIRE(replaced > 0);
    CHECK(left <= 1e-6 * replaced);
  }
}

TEST_CASE("Specular shoebox: a panel on one image path removes exactly that path",
          "[specular]") {
  // Material 1 scatters fully, so no exact path reflects off the panel itself.
  SceneDesc scene = box(0.f, kSrc, kLis, 3);
  scene.materials.push_back(Material{"panel", Bands(0.1f), Bands(1.f)});
  const Panel panel = panelOnFloorPath();
  test::addPanel(scene.mesh, glm::vec3(panel.corner()), glm::vec3(panel.u), glm::vec3(panel.v),
                 1);
  const std::vector<Image> images = lattice(kRoom, kSrc, kLis, 3);
  const std::vector<Image> open = unblocked(images, panel);
  REQUIRE(open.size() == images.size() - 1);  // placed to block the floor's path only
  Simulation sim(scene);
  const std::vector<SpecularPath> paths = run(sim, kLis, kSrc, 4);
  std::printf("panel: %zu exact paths, lattice %zu minus 1 blocked\n", paths.size(),
              images.size());
  CHECK(matchLattice(paths, open, kLis, 0.0) == int(open.size()));
  CHECK(paths.size() == open.size());
  for (const SpecularPath& p : paths)
    for (uint32_t i = 0; i < p.order; ++i) CHECK(p.triangles[i] < 12);  // walls only
}

TEST_CASE("Specular paths: a moving object blocks a path in its current pose", "[specular]") {
  // The same panel as a moving object (local frame centred on it), parked outside the room.
  SceneDesc scene = box(0.f, kSrc, kLis, 3);
  scene.materials.push_back(Material{"panel", Bands(0.1f), Bands(1.f)});
  const Panel panel = panelOnFloorPath();
  ObjectDesc object;
  object.name = "panel";
  test::addPanel(object.mesh, glm::vec3(-0.5 * panel.u - 0.5 * panel.v), glm::vec3(panel.u),
                 glm::vec3(panel.v), 1);
  ObjectKeyframe parked;
  parked.position = {20.f, 1.f, 3.f};
  object.trajectory = {parked};
  scene.objects.push_back(object);
  const std::vector<Image> images = lattice(kRoom, kSrc, kLis, 3);
  const std::vector<Image> open = unblocked(images, panel);
  REQUIRE(open.size() == images.size() - 1);
  Simulation sim(scene);
  CHECK(matchLattice(run(sim, kLis, kSrc, 4), images, kLis, 0.0) == 62);
  const std::vector<SpecularPath> blocked =
      run(sim, kLis, kSrc, 1, {Pose{glm::vec3(panel.centre), glm::quat(1, 0, 0, 0)}});
  CHECK(matchLattice(blocked, open, kLis, 0.0) == 61);
  CHECK(blocked.size() == 61);
  // The blocked sequence was kept (tau = 1 s) and is valid again at once.
  CHECK(matchLattice(run(sim, kLis, kSrc, 1, {Pose{parked.position, parked.rotation}}), images,
                     kLis, 0.0) == 62);
}

TEST_CASE("Specular paths follow a moving source in the next frame", "[specular]") {
  Simulation sim(box(0.f, kSrc, kLis, 3));
  CHECK(matchLattice(run(sim, kLis, kSrc, 4), lattice(kRoom, kSrc, kLis, 3), kLis, 0.0) == 62);
  // Move the source by 0.97 m: the cached sequences are re-validated at the new position and
  // the frame's rays propose the rest; every delay is the new lattice's.
  const glm::vec3 moved = kSrc + glm::vec3(0.8f, 0.2f, -0.5f);
  const std::vector<SpecularPath> after = run(sim, kLis, moved, 1);
  std::printf("after the move: %zu exact paths\n", after.size());
  CHECK(matchLattice(after, lattice(kRoom, moved, kLis, 3), kLis, 0.0) == 62);
  CHECK(after.size() == 62);
}

TEST_CASE("Specular paths: two listeners in one pass, each its own lattice", "[specular]") {
  const glm::vec3 second{3.6f, 2.2f, 5.8f};
  Simulation sim(box(0.f, kSrc, kLis, 3));
  const ListenerSphere listeners[2] = {{kLis, 0.5f}, {second, 0.5f}};
  for (int f = 0; f < 4; ++f) sim.runFrame(std::span<const ListenerSphere>(listeners, 2), {kSrc});
  CHECK(matchLattice(sim.specularPaths(0, 0), lattice(kRoom, kSrc, kLis, 3), kLis, 0.0) == 62);
  CHECK(matchLattice(sim.specularPaths(0, 1), lattice(kRoom, kSrc, second, 3), second, 0.0) ==
        62);
  CHECK(sim.specularPaths(0, 0).size() == 62);
  CHECK(sim.specularPaths(0, 1).size() == 62);
}

TEST_CASE("Specular paths carry (1 - s)^k with scattering 0.5", "[specular]") {
  // Fewer rays stay specular (each reflection with probability 1 - s), so 8 frames of
  // candidates; the cache keeps what earlier frames found.
  Simulation sim(box(0.5f, kSrc, kLis, 3));
  const std::vector<SpecularPath> paths = run(sim, kLis, kSrc, 8);
  const std::vector<Image> images = lattice(kRoom, kSrc, kLis, 3);
  std::printf("shoebox s=0.5: %zu exact paths of %zu\n", paths.size(), images.size());
  CHECK(matchLattice(paths, images, kLis, 0.5) == 62);
  CHECK(paths.size() == 62);
}

namespace {

/// Total band-4 energy of a frame: the energy response plus (when present) the exact paths.
struct Totals {
  double response = 0, exact = 0, responseEarly = 0, exactEarly = 0;
  size_t paths = 0;
};

Totals frameTotals(uint64_t seed, int exactOrder, int warmup) {
  SceneDesc scene = box(0.5f, kSrc, kLis, exactOrder);
  scene.propagation.seed = seed;
  scene.propagation.raysPerFrame = 4096;
  Simulation sim(scene);
  for (int f = 0; f <= warmup; ++f) sim.runFrame(kLis, {kSrc});
  Totals t;
  const EnergyResponse& er = sim.result(0).energy;
  for (size_t k = 0; k < er.binCount(); ++k) {
    t.response += er.bins()[k][4];
    if (k < 50) t.responseEarly += er.bins()[k][4];
  }
  EnergyResponse exact(er.binCount() * er.binSeconds(), er.binSeconds());
  addSpecularPaths(sim.specularPaths(0, 0), exact);
  t.paths = sim.specularPaths(0, 0).size();
  for (size_t k = 0; k < exact.binCount(); ++k) {
    t.exact += exact.bins()[k][4];
    if (k < 50) t.exactEarly += exact.bins()[k][4];
  }
  return t;
}

double mean(const std::vector<double>& x) {
  double m = 0;
  for (double v : x) m += v;
  return m / double(x.size());
}

double standardError(const std::vector<double>& x) {
  const double m = mean(x);
  double s2 = 0;
  for (double v : x) s2 += (v - m) * (v - m);
  return std::sqrt(s2 / double(x.size() - 1) / double(x.size()));
}

}  // namespace

TEST_CASE("Nothing counted twice: response + exact paths = plain path tracing",
          "[specular][statistics]") {
  // Shoebox, s = 0.5, 4096 rays, frame 16 of each seed (the exact paths' cache warmed for
  // tau = 1 s, so that it holds every sequence: a valid sequence no ray has proposed yet
  // is missing from the exact paths while its rays' hits are already left out), 1 kHz band. Paired: the same seed traces the same rays with and without exact
  // paths, so the difference is the exact energy minus the hits it replaced; unpaired: the
  // sums of different seeds. Both must agree within 3 standard errors estimated from the seeds.
  const int seeds = 20, warmup = 15;
  std::vector<double> withExact, plain, paired, pairedEarly, exactTotal, pathCount;
  for (int k = 0; k < seeds; ++k) {
    const Totals a = frameTotals(uint64_t(100 + k), 3, warmup);
    const Totals b = frameTotals(uint64_t(100 + k), 0, warmup);
    const Totals c = frameTotals(uint64_t(1000 + k), 0, warmup);
    withExact.push_back(a.response + a.exact);
    plain.push_back(c.response);
    paired.push_back(a.response + a.exact - b.response);
    pairedEarly.push_back(a.responseEarly + a.exactEarly - b.responseEarly);
    exactTotal.push_back(a.exact);
    pathCount.push_back(double(a.paths));
    CHECK(b.exact == 0.0);
  }
  const double d = mean(paired), se = standardError(paired);
  const double de = mean(pairedEarly), see = standardError(pairedEarly);
  const double u = mean(withExact) - mean(plain);
  const double seU = std::hypot(standardError(withExact), standardError(plain));
  std::printf("energy balance: %.1f exact paths of 62 per frame carrying %.4e\n",
              mean(pathCount), mean(exactTotal));
  std::printf("energy balance, 1 kHz: plain %.5e; paired difference %+.3e +- %.1e (%.2f se), "
              "first 50 ms %+.3e +- %.1e; unpaired %+.3e +- %.1e (%.2f se)\n",
              mean(plain), d, se, d / se, de, see, u, seU, u / seU);
  CHECK(std::abs(d) < 3 * se);
  CHECK(std::abs(de) < 3 * see);
  CHECK(std::abs(u) < 3 * seU);
}

TEST_CASE("Exact paths off, or no specular reflection: the energy response is unchanged",
          "[specular]") {
  // With scattering 1 no reflection is specular, so exact_order 3 must leave every ray and
  // every hit as exact_order 0 does, bit for bit, and find no path.
  for (Estimator e : {Estimator::kPathTracing, Estimator::kDpc}) {
    SceneDesc off = box(1.f, kSrc, kLis, 0), on = box(1.f, kSrc, kLis, 3);
    off.propagation.estimator = on.propagation.estimator = e;
    Simulation a(off), b(on);
    for (int f = 0; f < 3; ++f) {
      a.runFrame(kLis, {kSrc});
      b.runFrame(kLis, {kSrc});
      CHECK(test::identical(a.result(0).energy, b.result(0).energy));
      CHECK(a.specularPaths(0).empty());
      CHECK(b.specularPaths(0).empty());
    }
  }
}

// Oracle: geometry: a partition from wall to wall and floor to ceiling seals the listener's
// half of the shoebox from the source's, so no image path reaches it (every one folds across
// the partition's plane); only the rays that the partition transmits (R = 20 dB, so that they
// find reflection sequences on the listener's side) may. With source and listener mirror
// images of each other in the partition at one height, the floor's and the ceiling's
// reflection points lie on the partition's foot and top: both legs end on its edge, and a
// check of the legs alone let those paths through the solid partition (+6 dB at 1 kHz there
// against 1 mm either side). Checked at the mirror position and 1 mm either side.
TEST_CASE("Specular paths: none through a partition whose foot the reflection point is on",
          "[specular]") {
  const glm::vec3 src{2.5f, 1.5f, 3.5f};
  SceneDesc scene = box(0.f, src, {7.5f, 1.5f, 3.1f}, 2);
  Material partition{"partition", Bands(0.1f), Bands(0.f)};
  partition.transmissionLossDb = Bands(20.f);
  scene.materials.push_back(partition);
  test::addPanel(scene.mesh, {5.f, 0.f, 0.f}, {0.f, 3.f, 0.f}, {0.f, 0.f, 7.f}, 1);
  Simulation sim(scene);
  for (float dx : {0.f, -1e-3f, 1e-3f}) {
    const glm::vec3 lis{7.5f + dx, 1.5f, 3.1f};
    const std::vector<SpecularPath> paths = run(sim, lis, src, 3);
    INFO("listener x = " << lis.x << ": " << paths.size() << " exact paths");
    for (const SpecularPath& p : paths)
      INFO("order " << p.order << " delay " << p.delaySeconds << " s");
    CHECK(paths.empty());
  }
}
