// Which triangles of a mesh form one connected surface (scene/mesh_topology.h): panels that
// share corners are one surface, a leaf meshed a gap apart from its frame is another, and an
// exporter's corner written once per face changes nothing. The expected grouping is the one
// each mesh is built with.
#include "scene/mesh_topology.h"

#include <catch2/catch.hpp>
#include <glm/vec3.hpp>

#include "testing/test_scenes.h"

using namespace dpc;

TEST_CASE("Connected surfaces: a frame's panels are one, a leaf a gap apart is another",
          "[scene]") {
  Mesh m;
  const glm::vec3 y{0, 1, 0}, z{0, 0, 1};
  test::addPanel(m, {6, 0, 0}, 2.f * z, 2.1f * y, 0);       // jamb panel
  test::addPanel(m, {6, 2.1f, 0}, 2.f * z, 0.9f * y, 0);    // above it, sharing its top edge
  test::addPanel(m, {6, 0, 2.01f}, 0.98f * z, 2.09f * y, 0);  // leaf, 10 mm from the jamb
  test::addPanel(m, {6, 2.1f, 2}, 1.f * z, 0.9f * y, 0);    // lintel, sharing a corner only
  const std::vector<uint32_t> s = connectedSurfaces(m);
  REQUIRE(s.size() == m.triangles.size());
  const size_t perPanel = s.size() / 4;
  for (size_t t = 0; t < s.size(); ++t) CHECK(s[t] == (t / perPanel == 2 ? 1u : 0u));
}

TEST_CASE("Connected surfaces: a corner written once per face is still one point", "[scene]") {
  Mesh shared;
  const glm::vec3 x{1, 0, 0}, y{0, 1, 0}, z{0, 0, 1};
  test::addPanel(shared, {0, 0, 0}, x, y, 0);
  test::addPanel(shared, {0, 0, 0}, z, x, 0);
  test::addPanel(shared, {5, 0, 0}, x, y, 0);
  Mesh split;  // every triangle with corners of its own, as some exporters write them
  for (const auto& t : shared.triangles) {
    const uint32_t base = uint32_t(split.vertices.size());
    for (uint32_t v : t) split.vertices.push_back(shared.vertices[v]);
    split.triangles.push_back({base, base + 1, base + 2});
    split.materialIndex.push_back(0);
  }
  const std::vector<uint32_t> a = connectedSurfaces(shared), b = connectedSurfaces(split);
  CHECK(a == b);
  const size_t perPanel = a.size() / 3;
  for (size_t t = 0; t < a.size(); ++t) CHECK(a[t] == (t / perPanel == 2 ? 1u : 0u));
}
