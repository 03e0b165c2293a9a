// The diffraction edge finder (engine/diffraction.h) on every shipped scene: the same edges,
// bit for bit, as the exhaustive search it replaced (each edge tested against every triangle),
// recorded here as a count and a hash of the sorted edge list. Re-recorded when a double-sided
// face's second copy stopped adding its edges: a double-sided sheet's rim (two_rooms'
// partition, the terrains' panels), used by both copies, had been a wedge of `open` 0 and is now a
// free edge of open 2 pi, the same half-plane (the same count of edges; the air wedge 2 pi
// either way).
#include <catch2/catch.hpp>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <glm/vec2.hpp>
#include <string>

#include "engine/diffraction.h"
#include "scene/scene.h"
#include "testing/terrain.h"
#include "testing/test_scenes.h"

using namespace dpc;

namespace {

/// FNV-1a over the bytes of every field of every edge, in the finder's (sorted) order.
uint64_t edgeHash(const std::vector<DiffractionEdge>& edges) {
  uint64_t h = 1469598103934665603ull;
  auto add = [&h](const void* p, size_t n) {
    for (size_t i = 0; i < n; ++i)
      h = (h ^ static_cast<const unsigned char*>(p)[i]) * 1099511628211ull;
  };
  for (const DiffractionEdge& e : edges) {
    add(&e.a, sizeof e.a);
    add(&e.b, sizeof e.b);
    add(&e.direction, sizeof e.direction);
    add(&e.face0, sizeof e.face0);
    add(&e.normal0, sizeof e.normal0);
    add(&e.open, sizeof e.open);
    add(&e.length, sizeof e.length);
  }
  return h;
}

struct Golden {
  const char* scene;
  size_t edges;
  uint64_t hash;
};

}  // namespace

TEST_CASE("Diffraction edges: the shipped scenes keep their edges", "[diffraction]") {
  // The hall's balcony front edge is cut where the four pillars' faces, flush with the
  // balcony's front, run on past it (engine/sealed_edges.h): 9343 -> 9347 edges.
  const Golden golden[] = {
      {"shoebox", 12, 0x011ca3bf1a9fd443ull},    {"shoebox-corner", 13, 0xefc66783e07aa5f5ull},
      {"hall", 9347, 0xec7f89ca04d2fdd6ull},     {"two_rooms", 15, 0x73352147f10fd920ull},
      {"open_field", 20, 0x60d30ed49e87eccbull},
  };
  for (const Golden& g : golden) {
    const SceneDesc s = loadScene(std::string(DPC_SOURCE_DIR "/scenes/") + g.scene + ".json");
    const EdgeDiffraction d(s.mesh);
    INFO(g.scene);
    CHECK(d.edges().size() == g.edges);
    CHECK(edgeHash(d.edges()) == g.hash);
  }
}

TEST_CASE("Diffraction edges: generated terrains with panels keep their edges", "[diffraction]") {
  struct Terrain {
    uint32_t cells, panels;
    size_t edges;
    uint64_t hash;
  };
  const Terrain golden[] = {{24, 3, 420, 0xc56b1eea41a546bbull},
                            {64, 12, 2159, 0xbb7019cf92d3a5bdull}};
  for (const Terrain& g : golden) {
    const EdgeDiffraction d(test::terrain(g.cells, g.panels));
    INFO(g.cells << " cells, " << g.panels << " panels");
    CHECK(d.edges().size() == g.edges);
    CHECK(edgeHash(d.edges()) == g.hash);
    // Each panel's top rim (y = 2 m, above any terrain) diffracts; its rim along the flat
    // floor (y = 0, 1.5 m long: the terrain's edges are 0.5 m or diagonal) is sealed by it.
    size_t tops = 0, floorRims = 0;
    for (const DiffractionEdge& e : d.edges()) {
      tops += e.a.y == 2.f && e.b.y == 2.f;
      floorRims += e.a.y == 0.f && e.b.y == 0.f && e.length == 1.5f;
    }
    CHECK(tops == g.panels);
    CHECK(floorRims == 0);
  }
}

TEST_CASE("Diffraction edges: a window in a wall meshed with T-junctions has the window's edges",
          "[diffraction]") {
  // A 10 x 10 m wall (x = 0) with a window 1 x 1 m meshed as exporters write it without
  // splitting: two strips the wall's full height beside the window, a panel below and one
  // above it between them, whose corners lie on the strips' edges (T-junctions). The oracle is
  // the window's outline: its four sides, each 1 m, are the edges inside the wall (the rest
  // are the wall's outer rims). In the middle of the wall and off it: there a strip's edge
  // has its midpoint on a panel's side. Before engine/sealed_edges.h, a strip's edge beside
  // the middle window, whose midpoint lies in the window, was one free edge 10 m long, and
  // beside the window off the middle the strips' edges were sealed whole (their midpoints on
  // the panels' sides), so that window had no jambs.
  for (const glm::vec2 corner : {glm::vec2(4.5f, 4.5f), glm::vec2(6.5f, 2.f)}) {
    const float y0 = corner.x, z0 = corner.y;
    SceneDesc s;
    const glm::vec3 y{0, 1, 0}, z{0, 0, 1};
    test::addPanel(s.mesh, {0, 0, 0}, z0 * z, 10.f * y, 0);
    test::addPanel(s.mesh, {0, 0, z0 + 1.f}, (9.f - z0) * z, 10.f * y, 0);
    test::addPanel(s.mesh, {0, 0, z0}, 1.f * z, y0 * y, 0);
    test::addPanel(s.mesh, {0, y0 + 1.f, z0}, 1.f * z, (9.f - y0) * y, 0);
    const EdgeDiffraction d(s.mesh);
    int inside = 0;
    float insideLength = 0.f;
    for (const DiffractionEdge& e : d.edges()) {
      auto onRim = [](const glm::vec3& p) {
        return p.y < 1e-4f || p.y > 10.f - 1e-4f || p.z < 1e-4f || p.z > 10.f - 1e-4f;
      };
      if (onRim(e.a) && onRim(e.b)) continue;  // the wall's outer rim
      ++inside;
      insideLength += e.length;
      INFO("window at (" << y0 << ", " << z0 << "): edge from (" << e.a.y << ", " << e.a.z
                         << ") to (" << e.b.y << ", " << e.b.z << ")");
      CHECK(e.length == Approx(1.f).margin(1e-4));
      for (const glm::vec3& p : {e.a, e.b}) {  // on the window's outline
        CHECK(p.y > y0 - 1e-4f);
        CHECK(p.y < y0 + 1.f + 1e-4f);
        CHECK(p.z > z0 - 1e-4f);
        CHECK(p.z < z0 + 1.f + 1e-4f);
      }
    }
    INFO("window at (" << y0 << ", " << z0 << ")");
    CHECK(inside == 4);
    CHECK(insideLength == Approx(4.f).margin(1e-3));
  }
}
