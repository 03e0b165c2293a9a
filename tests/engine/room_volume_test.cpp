#include "engine/room_volume.h"

#include <catch2/catch.hpp>

#include "testing/test_scenes.h"

using namespace dpc;

TEST_CASE("Room volume: closed mesh by the divergence theorem, open mesh by its bounding box",
          "[room_volume]") {
  // A closed box gives its volume exactly (float vertices: 1e-9 relative), whatever the winding.
  SceneDesc s = test::makeShoebox({10.f, 3.f, 7.f}, Bands(0.1f), 0.5f, {2, 1.5f, 2}, {7, 1.5f, 5});
  CHECK(roomVolume(s.mesh) == Approx(210.0).epsilon(1e-9));
  for (auto& t : s.mesh.triangles) std::swap(t[1], t[2]);
  CHECK(roomVolume(s.mesh) == Approx(210.0).epsilon(1e-9));
  // A closed tetrahedron: a^3/6, a sixth of its bounding box.
  Mesh tet;
  tet.vertices = {{0, 0, 0}, {3, 0, 0}, {0, 3, 0}, {0, 0, 3}};
  tet.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  CHECK(roomVolume(tet) == Approx(4.5).epsilon(1e-9));
  // The same tetrahedron with each face's corners written separately (as some exporters do)
  // is still closed: its edges are matched by position.
  Mesh split;
  for (const auto& t : tet.triangles) {
    const uint32_t base = uint32_t(split.vertices.size());
    for (uint32_t v : t) split.vertices.push_back(tet.vertices[v]);
    split.triangles.push_back({base, base + 1, base + 2});
  }
  CHECK(roomVolume(split) == Approx(4.5).epsilon(1e-9));
  // Open: drop one triangle of the box (a missing ceiling half): bounding box, 210 m^3.
  s.mesh.triangles.pop_back();
  CHECK(roomVolume(s.mesh) == Approx(210.0).epsilon(1e-9));
  tet.triangles.pop_back();
  CHECK(roomVolume(tet) == Approx(27.0).epsilon(1e-9));
}
