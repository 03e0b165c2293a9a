// Direction sampling shared by the propagator and the bare-tracer benchmark (one definition, so
// the benchmark traces the propagator's rays). Any thread; no allocation; no errors.
#pragma once

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include <numbers>

#include "common/random.h"

namespace dpc {

/// A unit vector uniformly distributed on the sphere (z uniform in [-1, 1], azimuth uniform).
inline glm::vec3 uniformSphere(Rng& rng) {
  const float z = 1.f - 2.f * rng.uniform();
  const float r = std::sqrt(std::max(0.f, 1.f - z * z));
  const float phi = 2.f * std::numbers::pi_v<float> * rng.uniform();
  return {r * std::cos(phi), r * std::sin(phi), z};
}

/// Cosine-weighted direction about unit normal n (Malley's method: uniform on the disc, lifted
/// to the hemisphere). The orthonormal basis is Duff et al., "Building an Orthonormal Basis,
/// Revisited", JCGT 6(1), 2017.
inline glm::vec3 cosineHemisphere(const glm::vec3& n, Rng& rng) {
  const float sign = std::copysign(1.f, n.z);
  const float a = -1.f / (sign + n.z);
  const float b = n.x * n.y * a;
  const glm::vec3 t(1.f + sign * n.x * n.x * a, sign * b, -sign * n.x);
  const glm::vec3 bt(b, sign + n.y * n.y * a, -n.y);
  const float u1 = rng.uniform(), u2 = rng.uniform();
  const float r = std::sqrt(u1);
  const float phi = 2.f * std::numbers::pi_v<float> * u2;
  const float z = std::sqrt(std::max(0.f, 1.f - u1));
  return glm::normalize(t * (r * std::cos(phi)) + bt * (r * std::sin(phi)) + n * z);
}

}  // namespace dpc
