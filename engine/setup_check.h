// Setups that load but cannot be meant, found before a render by casting a few rays: a
// listener or source outside the room, a listener sphere larger than the room. Each gives a
// one-line warning (the render still runs: an open scene or a deliberate test may want it).
// Control thread; builds its own tracer (Embree) over the static mesh (milliseconds for the shipped
// scenes); allocates.
#pragma once

#include <glm/vec3.hpp>
#include <string>
#include <vector>

#include "scene/scene.h"

namespace dpc {

/// A listener radius below this fraction of its nearest surface's distance is warned about:
/// at 1/1000 the sphere is hit 10^6 times less often than one reaching that surface.
inline constexpr float kTinyRadiusFraction = 1e-3f;

/// Directions cast from each point (a Fibonacci sphere: near-uniform, deterministic).
inline constexpr int kSetupCheckDirections = 64;

/// Direction i (0 .. kSetupCheckDirections - 1) of the check: a unit vector on the Fibonacci
/// sphere. Any thread; no allocation.
glm::vec3 setupCheckDirection(int i);

/// Warnings for the scene's listeners and sources, at time 0 and at their trajectories'
/// keyframes (up to 32 of each, spread evenly):
/// - a point is "enclosed" when every direction hits the static mesh; when some points are
///   enclosed and others are not, each one that is not is outside the room (or the room has a
///   hole it can see through): its rays escape, and no sound connects it with the others (one
///   warning per listener or source, at its first such time);
/// - every point farther outside the mesh's bounding box than the box's diagonal: the mesh's
///   units or offset differ from the positions' (an export in centimetres, a level moved);
/// - a source inside a listener's sphere at time 0: its direct sound is read at R/2;
/// at time 0:
/// - a listener whose sphere radius exceeds the farthest surface seen from its centre contains
///   the whole room: the energy response counts every ray segment it holds;
/// - a listener sphere that reaches through a surface (radius larger than the nearest hit)
///   counts paths on both sides of that surface;
/// - a listener sphere smaller than kTinyRadiusFraction of the distance to the nearest
///   surface is hit by almost no ray (hits scale with its area): its responses stay empty.
std::vector<std::string> setupWarnings(const SceneDesc& scene);

}  // namespace dpc
