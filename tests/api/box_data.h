// A small scene built in code for the C API tests: a 6 x 4 x 3 m box with a source and a
// listener inside, as dpc_scene_data.
#pragma once

#include <cstdint>
#include <vector>

#include "dpc/dpc.h"

namespace dpc::test {

/// A 6 x 4 x 3 m box (12 triangles, one material), a source and a listener inside.
struct BoxData {
  std::vector<float> vertices = {0, 0, 0, 6, 0, 0, 6, 3, 0, 0, 3, 0,
                                 0, 0, 4, 6, 0, 4, 6, 3, 4, 0, 3, 4};
  std::vector<uint32_t> indices = {0, 1, 2, 0, 2, 3, 4, 6, 5, 4, 7, 6, 0, 4, 5, 0, 5, 1,
                                   3, 2, 6, 3, 6, 7, 0, 3, 7, 0, 7, 4, 1, 5, 6, 1, 6, 2};
  std::vector<uint32_t> materials = std::vector<uint32_t>(12, 0);
  dpc_material material{"walls", {0.1f, 0.1f, 0.1f, 0.1f, 0.1f, 0.1f, 0.1f, 0.1f}, 0.2f};
  std::vector<dpc_source> sources = {dpc_source{{2.f, 1.5f, 2.f}, 0.f, nullptr, 0, 0}};
  std::vector<dpc_listener> listeners;
  std::vector<dpc_source_directivity> directivities;  ///< empty: every source omni
  dpc_scene_data d{};

  BoxData() { dpc_scene_data_init(&d); }

  /// The data with every pointer set (call after changing the vectors).
  const dpc_scene_data& data() {
    d.mesh = dpc_mesh{vertices.data(), uint32_t(vertices.size() / 3), indices.data(),
                      uint32_t(indices.size() / 3), materials.data()};
    d.materials = &material;
    d.material_count = 1;
    d.sources = sources.data();
    d.source_count = int(sources.size());
    d.listener_position[0] = 4.f;
    d.listener_position[1] = 1.5f;
    d.listener_position[2] = 2.f;
    d.additional_listeners = listeners.empty() ? nullptr : listeners.data();
    d.source_directivities = directivities.empty() ? nullptr : directivities.data();
    return d;
  }
};

}  // namespace dpc::test
