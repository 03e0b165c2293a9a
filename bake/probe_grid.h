// The probes of a bake: a horizontal grid over the static mesh's bounding box, a 3-D lattice
// in a box (an audience area with raked seating, a balcony, a stairwell), or a list of
// positions, kept where a listener can stand. Control thread; builds its own tracer (Embree) over
// the static mesh; allocates; throws InputError naming the flag for a bad request.
//
// Grid: cell centres x = xmin + (i + 1/2) spacing, z = zmin + (j + 1/2) spacing over the
// mesh's bounding box, at y = ymin + height (the floor is the lowest point of the mesh; y is
// up as in the shipped scenes). Box: along each axis n = max(1, floor(extent / spacing)) points
// spaced `spacing` apart and centred in the box (a box thinner than the spacing gets one layer
// in its middle). Moving objects stand in their pose at t = 0 in the bake's traces, and the
// placement tests them there too (a probe on an open door leaf, or within the radius of it, is
// skipped as the static mesh's are).
// A candidate is skipped, and counted, when
//   - outside: a direction of the setup check's Fibonacci sphere (engine/setup_check.h) escapes
//     the mesh (outside a closed room, or the room has a hole it sees through);
//   - inside geometry: it is enclosed, but fewer than half of those directions hit a surface
//     from the air side. The air side is the side the normals point to when the mesh's signed
//     volume is negative (a room modelled from inside, as the shipped scenes are), else the
//     other; inside a solid (a pillar) a point sees the solid's inner side. A vote rather than
//     a crossing parity, so that single-sided inner walls (a partition) do not flip it;
//   - near a surface: the nearest surface is closer than the probe radius (the listener sphere
//     would count paths on both sides of it), a sheet through the point itself included.
#pragma once

#include <cstddef>
#include <cstdint>
#include <glm/vec3.hpp>
#include <string>
#include <vector>

#include "scene/scene.h"

namespace dpc::bake {

/// Most grid candidates one bake may test (a 1000 x 1000 grid): bounds the memory and time of
/// the placement, whatever the spacing.
inline constexpr size_t kMaxGridCandidates = 1'000'000;

struct GridRequest {
  double spacingM = 1.0;  ///< grid spacing, metres, > 0
  double heightM = 1.6;   ///< height above the floor, metres (a box: unused, 0)
  float radiusM = 0.5f;   ///< probe (listener sphere) radius, metres
  bool box = false;       ///< a 3-D lattice in [boxMin, boxMax] instead of the horizontal grid
  glm::vec3 boxMin{0.f}, boxMax{0.f};  ///< the box's corners, metres (min < max per axis)
};

/// How the probes were laid out, for the bake file's probe_layout attribute: "grid", "list"
/// or "box x0 y0 z0 x1 y1 z1" (metres).
std::string probeLayout(const GridRequest& request, bool list);

struct ProbeGrid {
  std::vector<glm::vec3> positions;  ///< the kept probes, metres, row-major (x fastest)
  size_t candidates = 0;             ///< grid points tested
  size_t outside = 0;                ///< skipped: outside the closed mesh
  size_t insideGeometry = 0;         ///< skipped: inside a solid
  size_t nearSurface = 0;            ///< skipped: a surface within the radius
};

/// The candidate points of `request` over `scene`'s static mesh (before placement; metres).
/// Throws as makeProbeGrid for a bad spacing or box.
std::vector<glm::vec3> gridCandidates(const SceneDesc& scene, const GridRequest& request);
/// The field placeProbes names for a grid of `request`: "--box" or "--spacing/--height".
const char* gridField(const GridRequest& request);

/// The grid (or box lattice) of `request` over `scene`'s static mesh. Throws
/// InputError("command line", "--spacing", ...) for spacing <= 0 or more than
/// kMaxGridCandidates points, ("command line", "--box", ...) for a box that is not finite,
/// within the scene limits and of positive extent on every axis, and (`sceneFile`,
/// "--spacing/--height" or "--box", ...) when no candidate is kept.
ProbeGrid makeProbeGrid(const SceneDesc& scene, const GridRequest& request,
                        const std::string& sceneFile);

/// The candidates that pass the placement rules above, with the skipped counts. Throws
/// InputError(sceneFile, field, ...) when none does.
ProbeGrid placeProbes(const SceneDesc& scene, const std::vector<glm::vec3>& candidates,
                      float radius, const std::string& sceneFile, const std::string& field);

/// Largest probe list file read, bytes (a million lines of three coordinates).
inline constexpr std::uintmax_t kMaxProbeListBytes = 64u << 20;

/// Probe positions from a text file: one probe per line, "x y z" or "x,y,z" in metres, '#'
/// starts a comment, blank lines skipped. Throws InputError(path, "line N", ...) for a line
/// that is not three finite coordinates within the scene limits, and (path, "", ...) for a
/// missing, oversized or empty file.
std::vector<glm::vec3> readProbeList(const std::string& path);

}  // namespace dpc::bake
