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

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <glm/vec3.hpp>
#include <limits>

#include "common/random.h"

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

/// Order-adaptive grouping: which hits the cache treats as "the same path".
///
/// Orders d <= fullOrder keep the thesis identifier (the whole patch sequence, above). Beyond
/// it the identifier is {S, last triangle, length bin, L}, the length bin floor(r / lengthBin)
/// with lengthBin = c times the energy response's bin width. Why this is allowed: every dpc
/// estimator is linear in the per-frame sums of a group's hits, so grouping never changes the
/// expected energy; it changes only where a group's energy lands (its mean delay) and how many
/// groups the cache holds. Hits grouped by length bin have their mean delay in the same energy
/// response bin, so the energy response is the one of the full identifier up to float rounding,
/// while the number of high-order groups is bounded by triangles x length bins instead of
/// growing with the rays (the thesis notes that patch sequences stop repeating at high orders,
/// which is what fills the cache). The last triangle keeps the arrival side for directional
/// responses. fullOrder is the reflection order at the mixing time, after which the field is
/// diffuse and arrivals depend statistically on delay only: t_mix = sqrt(V) ms (Polack's
/// estimate, V in m^3), reached after d = t_mix c S / (4 V) reflections (the mean reflection
/// rate c S / (4 V), Kuttruff, Room Acoustics, section 5.1), and at least kMinFullOrder so that
/// the early, specular part keeps its paths.
struct PathKeyRule {
  static constexpr int kMinFullOrder = 3;
  int fullOrder = std::numeric_limits<int>::max();  ///< default: the thesis identifier
  float lengthBin = 0.343f;                         ///< metres

  /// The rule for a room of volume (m^3) and surface area (m^2), speed of sound c (m/s) and
  /// energy response bin width binSeconds.
  static PathKeyRule forRoom(double volume, double surfaceArea, double c, double binSeconds) {
    PathKeyRule r;
    const double tMix = std::sqrt(std::max(volume, 1.0)) * 1e-3;
    const double order = tMix * c * surfaceArea / (4.0 * std::max(volume, 1.0));
    r.fullOrder = std::max(kMinFullOrder, int(std::ceil(std::min(order, 1e6))));
    r.lengthBin = float(c * binSeconds);
    return r;
  }
};

/// One ray's path identifier while it reflects: the thesis hash and what the order-adaptive
/// identifier needs (emitter, first and last triangle, reflections so far). 24 bytes.
struct PathKey {
  uint64_t hash = 0;
  uint32_t source = 0;  ///< the emitter's index (a listener's when tracing from listeners)
  uint32_t firstTriangle = 0;
  uint32_t lastTriangle = 0;
  int order = 0;

  static PathKey start(uint32_t source) {
    return PathKey{pathHashStart(source), source, 0, 0, 0};
  }
  void add(uint32_t triangle, uint32_t zeta, uint32_t xi) {
    hash = pathHashAddPatch(hash, patchKey(triangle, zeta, xi));
    addTriangle(triangle);
  }
  /// add() for a reflection that takes the path beyond rule.fullOrder, where finish() reads
  /// only the triangles and the length: the patch and the hash are not needed (a ray spends
  /// most of its reflections there, so the tracing loop skips both).
  void addTriangle(uint32_t triangle) {
    if (order == 0) firstTriangle = triangle;
    lastTriangle = triangle;
    ++order;
  }
  /// Whether the next reflection needs its patch (add) or only its triangle (addTriangle).
  bool nextNeedsPatch(const PathKeyRule& rule) const { return order < rule.fullOrder; }
  /// The identifier of a hit at path length `length` (metres) on receiver `listener`.
  /// emitterIsListener: the rays leave the listener, so the triangle next to the listener (the
  /// arrival side kept beyond fullOrder) is the first one, not the last.
  uint64_t finish(uint32_t listener, float length, const PathKeyRule& rule,
                  bool emitterIsListener = false) const {
    if (order <= rule.fullOrder) return pathHashFinish(hash, listener);
    const uint64_t bin = uint64_t(std::max(0.f, length / rule.lengthBin));
    const uint32_t arrival = emitterIsListener ? firstTriangle : lastTriangle;
    uint64_t h = pathHashAddPatch(mix64(0x7a11c0de5eed0001ULL + source), arrival);
    return pathHashFinish(pathHashAddPatch(h, ~bin), listener);
  }
};

}  // namespace dpc
