// A still pair's exact paths (SpecularPathCache::update with the inputs of its last update)
// come from its last validations instead of new ones. The oracle is a second cache fed the
// same candidates whose geometry number changes every frame, so it validates every sequence
// every frame as the image-source construction defines: the two must agree bit for bit while
// the pair is still, after the listener moves, and after an object moves into a path.
#include <catch2/catch.hpp>
#include <cstring>
#include <glm/gtc/quaternion.hpp>
#include <vector>

#include "common/random.h"
#include "engine/embree_tracer.h"
#include "engine/geometry.h"
#include "engine/specular_path_cache.h"
#include "testing/test_scenes.h"

using namespace dpc;

namespace {

template <class T>
bool sameBits(const T& a, const T& b) {
  return std::memcmp(&a, &b, sizeof(T)) == 0;
}

bool samePath(const SpecularPath& a, const SpecularPath& b) {
  return a.key == b.key && a.order == b.order && sameBits(a.length, b.length) &&
         sameBits(a.delaySeconds, b.delaySeconds) && sameBits(a.intensity, b.intensity) &&
         sameBits(a.direction, b.direction) && a.triangles == b.triangles &&
         sameBits(a.points, b.points);
}

bool samePaths(const SpecularPathCache& a, const SpecularPathCache& b) {
  if (a.paths().size() != b.paths().size() || a.validKeys() != b.validKeys()) return false;
  for (size_t i = 0; i < a.paths().size(); ++i)
    if (!samePath(a.paths()[i], b.paths()[i])) return false;
  return true;
}

/// Every sequence of 1-3 of the box's six wall faces (repeats included, which never
/// validate), as rays could propose them.
std::vector<SpecularSequence> wallSequences(const CoplanarFaces& faces) {
  std::vector<uint32_t> walls;
  for (uint32_t t = 0; t < 12; ++t)
    if (faces.faceOf(t) == t) walls.push_back(t);
  REQUIRE(walls.size() == 6);
  std::vector<SpecularSequence> out;
  for (uint32_t a : walls) {
    out.push_back({{a}, 1});
    for (uint32_t b : walls) {
      out.push_back({{a, b}, 2});
      for (uint32_t c : walls) out.push_back({{a, b, c}, 3});
    }
  }
  return out;
}
/// The 10 x 3 x 7 m box with a 1 x 1 m panel as a moving object, parked outside the room at
/// first, and every wall sequence the rays could propose.
struct PanelBox {
  static constexpr glm::vec3 kSource{2.1f, 1.4f, 2.3f}, kListener{7.3f, 1.7f, 4.9f};
  SceneDesc scene = withPanel(test::makeShoebox({10, 3, 7}, Bands(0.1f), 0.f, kSource, kListener));
  Geometry geometry{scene.mesh, scene.materials, 0.5f, scene.objects};
  EmbreeTracer tracer{scene.mesh, scene.objects};
  SpecularScene specular{scene.mesh, scene.objects, geometry, tracer, Bands(0.f), 343.f};
  std::vector<SpecularSequence> sequences = wallSequences(specular.faces());
  Rng rng{41, 7};

  static SceneDesc withPanel(SceneDesc s) {
    ObjectDesc panel;
    panel.name = "panel";
    test::addPanel(panel.mesh, {-0.5f, -0.5f, 0.f}, {1.f, 0.f, 0.f}, {0.f, 1.f, 0.f}, 0);
    panel.trajectory = {ObjectKeyframe{0.0, {30.f, 1.f, 3.f}, {1.f, 0.f, 0.f, 0.f}}};
    s.objects.push_back(panel);
    return s;
  }
  /// A different 70 % of the sequences every frame, as the rays propose them.
  SpecularCandidates propose() {
    SpecularCandidates candidates;
    for (const SpecularSequence& s : sequences)
      if (rng.uniform() < 0.7f) candidates.insert(s);
    return candidates;
  }
  /// The panel in front of `listener`, facing it, 0.7 m away (the tracer's and the paths').
  void panelBefore(const glm::vec3& listener) {
    const Pose pose{listener + glm::vec3(-0.7f, 0.f, 0.f),
                    glm::angleAxis(glm::radians(90.f), glm::vec3(0.f, 1.f, 0.f))};
    tracer.setObjectPose(0, pose);
    tracer.commitPoses();
    specular.setObjectPose(0, pose);
  }
};

}  // namespace

TEST_CASE("Exact paths of a still pair are its last results bit for bit, and a moved listener "
          "or object validates them again",
          "[specular]") {
  PanelBox box;
  const glm::vec3 src = PanelBox::kSource, lis = PanelBox::kListener;
  SpecularPathCache still(1.0, 1.0 / 15), fresh(1.0, 1.0 / 15);
  uint64_t geometryVersion = 1;
  auto frame = [&](uint64_t f, glm::vec3 listener) {
    const SpecularCandidates candidates = box.propose();
    still.update(candidates, box.specular, {src, listener, 0.5f, geometryVersion}, f);
    fresh.update(candidates, box.specular, {src, listener, 0.5f, 1000 + f}, f);
    INFO("frame " << f << ": " << still.paths().size() << " and " << fresh.paths().size()
                  << " paths");
    REQUIRE(samePaths(still, fresh));
  };
  for (uint64_t f = 0; f < 6; ++f) frame(f, lis);
  const size_t open = still.paths().size();
  CHECK(open >= 20);  // most of the box's 62 paths up to order 3 proposed within 6 frames

  // The listener steps 1 m: every cached sequence is validated at the new position.
  const glm::vec3 moved = lis + glm::vec3(-1.f, 0.f, 0.f);
  for (uint64_t f = 6; f < 9; ++f) frame(f, moved);

  // The panel moves in front of the listener, facing it, 0.7 m away: paths behind it go.
  const size_t before = still.paths().size();
  box.panelBefore(moved);
  ++geometryVersion;
  for (uint64_t f = 9; f < 12; ++f) frame(f, moved);
  CHECK(still.paths().size() < before);
}

TEST_CASE("A still pair's exact paths stand without validation until its source moves",
          "[specular]") {
  // Equal inputs are the whole key: the panel moved in front of the listener without a new
  // geometry number leaves the still pair's paths as they were (they are not validated
  // again), while a cache given a new number loses the paths the panel blocks. A 1 m step of
  // the source then validates every sequence again (bit for bit the fresh cache's).
  PanelBox box;
  const glm::vec3 src = PanelBox::kSource, lis = PanelBox::kListener;
  SpecularPathCache still(1.0, 1.0 / 15), fresh(1.0, 1.0 / 15);
  for (uint64_t f = 0; f < 6; ++f) {
    const SpecularCandidates candidates = box.propose();
    still.update(candidates, box.specular, {src, lis, 0.5f, 1}, f);
    fresh.update(candidates, box.specular, {src, lis, 0.5f, 1000 + f}, f);
  }
  const std::vector<SpecularPath> open = still.paths();
  box.panelBefore(lis);
  for (uint64_t f = 6; f < 9; ++f) {
    const SpecularCandidates candidates = box.propose();
    still.update(candidates, box.specular, {src, lis, 0.5f, 1}, f);
    fresh.update(candidates, box.specular, {src, lis, 0.5f, 1000 + f}, f);
  }
  CHECK(fresh.paths().size() < open.size());
  REQUIRE(still.paths().size() >= open.size());  // new candidates may add, none go
  for (const SpecularPath& p : open) CHECK(still.validKeys().count(p.key) == 1);

  const glm::vec3 stepped = src + glm::vec3(1.f, 0.f, 0.f);
  for (uint64_t f = 9; f < 12; ++f) {
    const SpecularCandidates candidates = box.propose();
    still.update(candidates, box.specular, {stepped, lis, 0.5f, 1}, f);
    fresh.update(candidates, box.specular, {stepped, lis, 0.5f, 1000 + f}, f);
    INFO("frame " << f);
    REQUIRE(samePaths(still, fresh));
  }
}
