// The same geometry wound the other way (engine/diffraction.h SurfaceBodies::outward):
// exporters differ in which way a triangle's corners turn (glTF's front faces are counter-
// clockwise, many OBJ writers' are not), and a solid object's faces may come out pointing into
// it. The direct sound and its diffraction depend on where the surfaces are, not on which way
// they face: every band must read the same, wound either way.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <utility>

#include "scene/scene.h"
#include "testing/test_scenes.h"
#include "tests/engine/door_scenes.h"

using namespace dpc;
using namespace dpc::door_test;

namespace {

/// The mesh with every triangle's winding reversed from triangle `from` on (a solid object's
/// faces turned inward, or with `from` 0 the whole file as another exporter writes it).
Mesh rewound(Mesh mesh, size_t from = 0) {
  for (size_t t = from; t < mesh.triangles.size(); ++t)
    std::swap(mesh.triangles[t][1], mesh.triangles[t][2]);
  return mesh;
}

/// Checks that the direct sound at each listener reads the same in every band with the mesh
/// wound as given and rewound from triangle `from` on: to 0.01 dB (single-precision sums; the
/// geometry is the same to the bit).
void checkSameEitherWay(const char* what, const SceneDesc& scene, const glm::vec3& source,
                        std::initializer_list<glm::vec3> listeners, size_t from = 0) {
  SceneDesc other = scene;
  other.mesh = rewound(scene.mesh, from);
  for (const glm::vec3& listener : listeners) {
    const Bands a = decibels(directLevel(scene, source, listener));
    const Bands b = decibels(directLevel(other, source, listener));
    std::printf("%-28s z %.3f:", what, double(listener.z));
    for (int k = 0; k < kNumBands; ++k) std::printf(" %6.1f/%6.1f", double(a[k]), double(b[k]));
    std::printf("\n");
    for (int k = 0; k < kNumBands; ++k) {
      INFO(what << ", listener z " << listener.z << ", band " << k);
      CHECK(std::abs(a[k] - b[k]) <= 0.01f);
    }
  }
}

}  // namespace

TEST_CASE("Winding: staggered posts wound inside out read as wound outward", "[diffraction]") {
  // Three rows of 10 cm posts 15 cm apart, the middle row staggered, in free space. Wound
  // inside out, every gap between them read covered (path_slits.cpp coveredFace) and the
  // listener behind a post heard nothing from 250 Hz up (-300 dB) where wound outward it reads
  // -7 to -14 dB.
  SceneDesc s = test::makeShoebox({12, 3, 5}, Bands(0.2f), 0.3f, kSource, kListener, 0.5f);
  s.mesh = Mesh{};
  for (int row = 0; row < 3; ++row)
    for (int k = -9; k <= 9; ++k) {
      const float x = 0.15f * float(row - 1), z = 0.15f * (float(k) + 0.5f * float(row % 2));
      if (std::abs(z) <= 1.45f)
        test::addSolidBox(s.mesh, {x - 0.05f, 0.f, z - 0.05f}, {x + 0.05f, 2.f, z + 0.05f}, 0);
    }
  checkSameEitherWay("staggered posts", s, {-3.f, 1.2f, 0.f},
                     {{3.f, 1.2f, 0.f}, {3.f, 1.2f, 0.05f}, {3.f, 1.2f, 0.12f}});
}

TEST_CASE("Winding: a door leaf in its frame reads the same wound either way",
          "[diffraction][door]") {
  // A box leaf 4 cm deep in a 0.2 m wall's doorway, 5 and 10 mm from the jambs and the lintel,
  // shut against a stop or standing free in the reveal; the whole file rewound (another
  // exporter), and only the leaf (a prop wound inside out).
  for (float gap : {0.005f, 0.01f}) {
    const SceneDesc stopped = stoppedLeafScene(0.2f, gap, 0.04f, 5.98f, 1.f, 0.03f);
    const SceneDesc free = recessedLeafScene(0.2f, gap, 0.04f, 6.f);
    const std::initializer_list<glm::vec3> at = {kListener, kListener + glm::vec3(0, 0, 1.f)};
    checkSameEitherWay("leaf against a stop", stopped, kSource, at);
    checkSameEitherWay("leaf in the reveal", free, kSource, at);
    const size_t leaf = thickDoorwayScene(0.2f, false).mesh.triangles.size();
    checkSameEitherWay("leaf alone rewound", free, kSource, at, leaf);
  }
}
