// Random numbers for Monte Carlo path tracing.
//
// Rng is PCG32 (M. E. O'Neill, "PCG: A Family of Simple Fast Space-Efficient Statistically
// Good Algorithms for Random Number Generation", HMC-CS-2014-0905): 64-bit state, 2^63
// selectable streams. dpc gives every ray its own stream, derived from (seed, frame, source,
// ray index), so a frame's result does not depend on how rays are split across threads.
// Any thread (one Rng per thread/ray); never allocates; no errors.
#pragma once

#include <cstdint>

namespace dpc {

/// 64-bit finaliser of MurmurHash3 (Appleby): a bijection with full avalanche.
constexpr uint64_t mix64(uint64_t x) {
  x ^= x >> 33;
  x *= 0xff51afd7ed558ccdULL;
  x ^= x >> 33;
  x *= 0xc4ceb9fe1a85ec53ULL;
  x ^= x >> 33;
  return x;
}

/// Combines values into one 64-bit seed (order matters).
constexpr uint64_t hashCombine(uint64_t h, uint64_t v) {
  return mix64(h ^ (mix64(v) + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2)));
}

class Rng {
 public:
  /// seed picks the position in the sequence, stream one of 2^63 independent sequences.
  constexpr Rng(uint64_t seed, uint64_t stream) : state_(0), inc_((stream << 1u) | 1u) {
    nextU32();
    state_ += seed;
    nextU32();
  }

  constexpr uint32_t nextU32() {
    uint64_t old = state_;
    state_ = old * 6364136223846793005ULL + inc_;
    uint32_t xorshifted = uint32_t(((old >> 18u) ^ old) >> 27u);
    uint32_t rot = uint32_t(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((~rot + 1u) & 31u));
  }

  /// Uniform float in [0, 1): 24 random mantissa bits.
  constexpr float uniform() { return float(nextU32() >> 8) * 0x1p-24f; }

 private:
  uint64_t state_, inc_;
};

}  // namespace dpc
