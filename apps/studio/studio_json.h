// dpc studio's documents: the scene and the bake's maps (sent once), a frame's state, the
// selected pair's energy response, and that response as dpc-demo --er-out's CSV (so
// dpc-analyze reads what the page shows). Control or server thread; allocates. Field names:
// docs/studio.md "API".
#pragma once

#include <cstdint>
#include <glm/vec3.hpp>
#include <string>
#include <vector>

#include "apps/studio/studio_board.h"
#include "scene/scene.h"

namespace dpc::studio {

/// The static mesh (vertices, triangles, material per triangle), the materials with their
/// absorption per band, the sources' and listeners' names, the band centres, and the bake's
/// file name (`bake`: "" is null, the page then asks for no /api/bake).
std::string sceneJson(const SceneDesc& scene, const std::string& bakeFile = "");

/// Parameter rows of a bake per probe and source: the octave bands, then broadband.
inline constexpr int kBakeRows = kNumBands + 1;

/// A bake's probe grid and parameter maps, as read from the file by dpc-demo
/// (apps/demo/studio_bake.h): plain values, no bake or HDF5 types.
struct StudioBake {
  std::string file;
  std::vector<glm::vec3> probes;        ///< probe centres, m
  std::vector<uint8_t> done;            ///< per probe: 1 where its data are stored
  size_t sources = 0;
  std::vector<std::string> parameters;  ///< the last axis of values (T20 .. G)
  /// [probe][source][row][parameter] and their 95 % half-widths; rows: kBakeRows.
  std::vector<float> values, ci95;
  std::vector<float> sti, stiCi95;      ///< [probe][source], broadband only
};

/// /api/bake: file, probes (flat x, y, z), done (0/1), sources, bands (the centres in Hz, then
/// "broadband"), parameters (the bake's names, then "STI"), values and ci95 flat as
/// [probe][source][row][parameter] with STI in the broadband row only; null for a value that
/// is not finite, for STI outside the broadband row and for every value of a probe not done.
std::string bakeJson(const StudioBake& bake);

/// Poses, the direct sound, the exact early paths and the figures of a frame (no response).
std::string stateJson(const StudioFrame& frame);

/// The selected pair's energy response per band, direct sound included: {"frame", "source",
/// "binSeconds", "onsetSeconds" (the direct sound's arrival, null when none), "origin": "bake"
/// (StudioFrame::fromBake) or "traced", "bands": [[...] x 8]}.
std::string responseJson(const StudioFrame& frame);

/// The selected pair's response as an energy-response CSV (analysis/energy_response_csv.h): the
/// direct sound (when visible and inside the response) on its "direct" row and out of its bin,
/// so that dpc-analyze reads the same numbers with t0 at its arrival, as the page does.
std::string energyCsv(const StudioFrame& frame);

}  // namespace dpc::studio
