// A large generated mesh for the load-time test and `dpc-bench load`: a terrain of square
// cells, flat on one half and bumpy on the other, with thin panels and solid crates on it.
// Control thread; allocates; no errors.
#pragma once

#include <cstdint>

#include "scene/scene.h"
#include "testing/test_scenes.h"

namespace dpc::test {

/// `cells` x `cells` square cells of 0.5 m in the x-z plane (2 cells^2 triangles, material 0),
/// vertex heights (y) 0 on the half x < cells / 4 m and a repeating pattern of 0, 0.25, ...,
/// 1 m on the other (every edge there is a wedge: 1 m over 0.5 m, not flat), then `panels`
/// double-sided 2 m x 1.5 m panels (4 triangles each, addPanel) standing on the terrain in
/// rows 2 m apart from the x = 0 side (cells / 8 panels per row): those on the flat half have
/// rims along the floor that lie in it (sealed: no diffraction). Every coordinate is a
/// multiple of 0.25 m, exact in float. Then `crates` solid 0.25 m cubes (addSolidBox: every
/// face a narrow face, engine/channel_path.h) in rows 0.5 m apart along z from x = z = 0.125 m,
/// 40 per row, standing at height 0 (on the flat half while it is wide enough).
inline Mesh terrain(uint32_t cells, uint32_t panels, uint32_t crates = 0) {
  Mesh m;
  const uint32_t n = cells + 1;
  for (uint32_t i = 0; i < n; ++i)
    for (uint32_t j = 0; j < n; ++j) {
      const bool bumpy = 2 * i >= cells;
      const float h = bumpy ? 0.25f * float((i * 7 + j * 13) % 5) : 0.f;
      m.vertices.push_back({0.5f * float(i), h, 0.5f * float(j)});
    }
  for (uint32_t i = 0; i < cells; ++i)
    for (uint32_t j = 0; j < cells; ++j) {
      const uint32_t v = i * n + j;
      m.triangles.push_back({v, v + 1, v + n + 1});
      m.triangles.push_back({v, v + n + 1, v + n});
    }
  m.materialIndex.assign(m.triangles.size(), 0);
  const uint32_t perRow = std::max(1u, cells / 8);  // panels 2 m apart along z
  for (uint32_t p = 0; p < panels; ++p) {
    const glm::vec3 corner{0.5f + 2.f * float(p / perRow), 0.f, 0.5f + 2.f * float(p % perRow)};
    addPanel(m, corner, {0.f, 0.f, 1.5f}, {0.f, 2.f, 0.f}, 0);
  }
  for (uint32_t c = 0; c < crates; ++c) {
    const glm::vec3 lo{0.125f + 0.5f * float(c / 40), 0.f, 0.125f + 0.5f * float(c % 40)};
    addSolidBox(m, lo, lo + glm::vec3(0.25f), 0);
  }
  return m;
}

}  // namespace dpc::test
