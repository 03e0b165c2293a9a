// Patch subdivision of triangles and the diffuse path identifier (Schissler thesis, 3.2.2).
//
// Each triangle is cut into rows and columns of patches about lambda x lambda metres, without
// storing the patches: a TrianglePatching (5 bytes) holds the row count N_zeta, the widest
// row's column count N_xi and the key vertex, and patchOf() finds the patch of a hit from its
// barycentric coordinates. Definitions (docs/design.md): key vertex v_k = the vertex with the
// longest altitude (opposite the shortest edge), h_k its altitude, e_k the opposite edge;
// N_zeta = ceil(h_k / lambda), N_xi = ceil(e_k / lambda), row zeta has
// N_xi^zeta = ceil((N_zeta - zeta) / N_zeta * N_xi) columns (thesis eq. 3.1).
// zeta = floor(gamma_k * N_zeta); the column index normalises gamma_a (v_a = the vertex after
// v_k in winding order) by the row's width (1 - gamma_k), so every column of a row spans the
// same share of it (the thesis' literal floor(gamma_a * N_xi^zeta) leaves part of each row
// unused). Indices are clamped to the valid range.
// Any thread; no allocation; no errors (degenerate triangles get one patch).
#pragma once

#include <array>
#include <cstdint>
#include <glm/vec3.hpp>

#include "engine/random.h"

namespace dpc {

struct TrianglePatching {
  uint16_t rows = 1;           ///< N_zeta >= 1 (clamped to 65535)
  uint16_t widestColumns = 1;  ///< N_xi >= 1 (clamped to 65535)
  uint8_t keyVertex = 0;       ///< index 0..2 of v_k in the triangle's winding order

  /// Builds the subdivision of triangle (p0, p1, p2) for patch size lambda (metres, > 0).
  static TrianglePatching build(const glm::vec3& p0, const glm::vec3& p1, const glm::vec3& p2,
                                float lambda);

  /// Columns in row zeta (eq. 3.1), >= 1.
  uint32_t columnsInRow(uint32_t zeta) const;

  /// Number of patches of the triangle.
  uint32_t patchCount() const;

  /// Patch (zeta, xi) of the point with barycentrics (gamma_0, gamma_1, gamma_2), which must
  /// sum to 1 (as Embree's (1-u-v, u, v)).
  std::array<uint32_t, 2> patchOf(const std::array<float, 3>& gamma) const;
};

/// A patch as one 64-bit value: triangle index (32 bits), zeta (16), xi (16).
constexpr uint64_t patchKey(uint32_t triangle, uint32_t zeta, uint32_t xi) {
  return (uint64_t(triangle) << 32) | (uint64_t(zeta & 0xffffu) << 16) | uint64_t(xi & 0xffffu);
}

/// Incremental 64-bit hash of the path identifier K = {S, T1(zeta1, xi1), ..., Td, L}.
/// Start with pathHashStart(source), fold in each reflection's patchKey in order with
/// pathHashAddPatch, and finish with pathHashFinish(listener). Order-sensitive; the path
/// length (reflection order) is implied by the sequence. Collisions: a 64-bit bijective
/// mixer per step, so two different sequences of equal length collide with probability
/// about 2^-64 (tests/engine/patch_test.cpp checks a million sequences).
constexpr uint64_t pathHashStart(uint32_t source) {
  return mix64(0x5eed0fd9c0ffee11ULL + source);
}
constexpr uint64_t pathHashAddPatch(uint64_t h, uint64_t key) {
  return mix64(h ^ mix64(key + 0x632be59bd9b4e019ULL));
}
constexpr uint64_t pathHashFinish(uint64_t h, uint32_t listener) {
  return mix64(h ^ (0xa0761d6478bd642fULL * (uint64_t(listener) + 1)));
}

}  // namespace dpc
