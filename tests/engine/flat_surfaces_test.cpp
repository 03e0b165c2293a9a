// Which triangles form one flat surface for the diffraction bounds (engine/diffraction_edges.h,
// flatSurfaces): coplanar panels of a wall are one, a leaf a gap apart from its frame is
// another, a leaf welded to its frame at the hinge but swung out of its plane is another too,
// the two copies of a double-sided sheet are one, and an exporter's corner written once per
// face changes nothing. The expected grouping is the one each mesh is built with.
#include <catch2/catch.hpp>
#include <cmath>
#include <glm/vec3.hpp>

#include "engine/diffraction_edges.h"
#include "testing/test_scenes.h"

using namespace dpc;

namespace {

/// Per panel of `panels` triangles each (test::addPanel writes 4: both sides), the surface of
/// its first triangle, after checking every triangle of the panel has it.
std::vector<uint32_t> panelSurfaces(const std::vector<uint32_t>& s, size_t panels) {
  const size_t per = s.size() / panels;
  std::vector<uint32_t> out;
  for (size_t p = 0; p < panels; ++p) {
    for (size_t t = p * per; t < (p + 1) * per; ++t) CHECK(s[t] == s[p * per]);
    out.push_back(s[p * per]);
  }
  return out;
}

}  // namespace

TEST_CASE("Flat surfaces: a wall's panels are one, a leaf beside or hinged to it another",
          "[diffraction]") {
  Mesh m;
  const glm::vec3 y{0, 1, 0}, z{0, 0, 1};
  test::addPanel(m, {6, 0, 0}, 2.f * z, 2.1f * y, 0);       // jamb panel
  test::addPanel(m, {6, 2.1f, 0}, 2.f * z, 0.9f * y, 0);    // above it, sharing its top edge
  test::addPanel(m, {6, 2.1f, 2}, 1.f * z, 0.9f * y, 0);    // lintel, sharing its side edge
  test::addPanel(m, {6, 0, 2.01f}, 0.98f * z, 2.09f * y, 0);  // leaf, closed, 10 mm from the jamb
  const float a = 1.396f;  // 80 degrees: a leaf hinged on the jamb's edge, swung open
  test::addPanel(m, {6, 0, 2}, glm::vec3(std::sin(a), 0, std::cos(a)), 2.1f * y, 0);
  const std::vector<uint32_t> s = panelSurfaces(flatSurfaces(m), 5);
  CHECK(s[0] == 0);
  CHECK(s[1] == 0);
  CHECK(s[2] == 0);
  CHECK(s[3] == 1);
  CHECK(s[4] == 2);  // welded to the jamb along the hinge, but 80 degrees out of its plane
}

TEST_CASE("Flat surfaces: a corner written once per face is still one point", "[diffraction]") {
  Mesh shared;
  const glm::vec3 x{1, 0, 0}, y{0, 1, 0}, z{0, 0, 1};
  test::addPanel(shared, {0, 0, 0}, x, y, 0);
  test::addPanel(shared, {1, 0, 0}, x, y, 0);  // coplanar, sharing an edge
  test::addPanel(shared, {0, 0, 0}, z, x, 0);  // at right angles
  Mesh split;  // every triangle with corners of its own, as some exporters write them
  for (const auto& t : shared.triangles) {
    const uint32_t base = uint32_t(split.vertices.size());
    for (uint32_t v : t) split.vertices.push_back(shared.vertices[v]);
    split.triangles.push_back({base, base + 1, base + 2});
    split.materialIndex.push_back(0);
  }
  const std::vector<uint32_t> a = flatSurfaces(shared), b = flatSurfaces(split);
  CHECK(a == b);
  CHECK(panelSurfaces(a, 3) == std::vector<uint32_t>{0, 0, 1});
}

TEST_CASE("Free-standing surfaces: a leaf and a box's faces stand free, a room's walls and a "
          "lintel panel between jambs do not",
          "[diffraction]") {
  // freeStandingExtents (engine/diffraction_edges.h): three quarters of a surface's boundary
  // must be edges that bound it as a free-standing surface's rim does.
  auto extents = [](const Mesh& m) {
    const std::vector<uint32_t> s = flatSurfaces(m);
    const std::vector<float> e =
        freeStandingExtents(m, s, surfaceBodies(m, s), candidateEdges(m, s));
    std::vector<float> perTriangle;
    for (uint32_t t : s) perTriangle.push_back(e[t]);
    return perTriangle;
  };
  // The shoebox: closed, 12 m across, a room: no wall stands free.
  const SceneDesc room = test::makeShoebox({10, 3, 7}, Bands(0.1f), 0.f, {2, 1, 2}, {8, 1, 5});
  for (float e : extents(room.mesh)) CHECK(std::isinf(e));
  // A wall meshed with T-junctions round a doorway: the jambs full height, a lintel panel between
  // them whose sides meet the jambs (sealed: 2 of its 3.8 m of boundary are free); a leaf beside
  // it, a gap from the wall (all its boundary free: it stands free, 1.7 m x 2.09 m across).
  Mesh wall;
  const glm::vec3 y{0, 1, 0}, z{0, 0, 1};
  test::addPanel(wall, {6, 0, 0}, 2.f * z, 3.f * y, 0);
  test::addPanel(wall, {6, 2.1f, 2}, 1.f * z, 0.9f * y, 0);
  test::addPanel(wall, {6, 0, 3}, 2.f * z, 3.f * y, 0);
  test::addPanel(wall, {6.01f, 0, 2.01f}, glm::vec3(0.7f, 0, 0.7f), 2.09f * y, 0);
  const std::vector<float> w = extents(wall);
  CHECK(std::isinf(w[4]));  // the lintel panel
  CHECK(w[12] == Approx(std::sqrt(0.98 + 2.09 * 2.09)).epsilon(1e-4));  // the leaf's diagonal
  // A solid box 1 m across: every face stands free.
  const Mesh box = test::solidBox(1.f);
  for (float e : extents(box)) CHECK(e == Approx(std::sqrt(2.0)).epsilon(1e-4));
}
