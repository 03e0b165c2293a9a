// The fixed listener-frame directions the spatial synthesiser renders its reverberant field
// from (synthesis/spatial_synthesizer.h): unit vectors, x forward, y left, z up. Any thread;
// allocates the returned vector; no errors.
#pragma once

#include <glm/vec3.hpp>
#include <vector>

namespace dpc {

/// The K = 8 listener-frame directions dpc uses: six on the horizon every 60 degrees from
/// straight ahead, one straight up, one 40 degrees below the front (KEMAR's lowest ring).
std::vector<glm::vec3> defaultSpatialDirections();

/// `count` >= 1 listener-frame directions spread evenly over the whole sphere (a spherical
/// Fibonacci lattice: González, "Measurement of areas on a sphere using Fibonacci and
/// latitude-longitude lattices", Math. Geosci. 42, 2010), the first near straight up. For
/// outputs whose sound field turns after synthesis (Ambisonics, head-tracked binaural), where
/// no direction relative to the head deserves more resolution than another.
std::vector<glm::vec3> uniformSpatialDirections(int count);

}  // namespace dpc
