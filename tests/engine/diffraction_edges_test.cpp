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
#include <string>

#include "engine/diffraction.h"
#include "scene/scene.h"
#include "testing/terrain.h"

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
  const Golden golden[] = {
      {"shoebox", 12, 0x011ca3bf1a9fd443ull},    {"shoebox-corner", 13, 0xefc66783e07aa5f5ull},
      {"hall", 9343, 0x15c774e48361b4e9ull},     {"two_rooms", 15, 0x73352147f10fd920ull},
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
