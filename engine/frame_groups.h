// One frame's listener hits, grouped by path identifier: what the propagator (engine/
// propagation.h) hands the estimators (engine/path_cache.h). A hit is one ray segment that
// crossed a listener sphere; a group sums the hits of one path (key) in the frame.
//
// Threads: the propagation thread that owns the groups. Allocation: FrameGroups grows as
// needed, then keeps its capacity (clear() keeps it). Errors: none.
#pragma once

#include <tsl/robin_map.h>

#include <cstddef>
#include <cstdint>
#include <glm/vec3.hpp>
#include <vector>

#include "common/bands.h"

namespace dpc {

/// One ray segment that crossed the listener sphere.
struct PathHit {
  /// surface of a hit whose path reflected nowhere (the direct sound).
  static constexpr uint32_t kNoSurface = 0xFFFFFFFFu;
  uint64_t key = 0;          ///< path identifier hash K (engine/patch.h)
  Bands intensity{0.f};      ///< I(omega) = band energy * air attenuation / (pi R^2), 1/m^2
  float length = 0.f;        ///< r, path length to the listener, metres
  glm::vec3 direction{0.f};  ///< unit vector from the listener toward the arriving sound
  /// The triangle (Geometry's numbering) the path reflected from last before the listener.
  uint32_t surface = kNoSurface;
};

/// A frame's hits grouped by path identifier, in order of each key's first hit.
class FrameGroups {
 public:
  struct Group {
    uint64_t key;
    uint32_t eta;         ///< hits this frame
    Bands intensity;      ///< summed I, 1/m^2
    float length;         ///< summed r, metres
    glm::vec3 direction;  ///< summed direction weighted by mean band intensity
  };
  void clear();
  void add(const PathHit& hit);
  const std::vector<Group>& groups() const { return groups_; }
  size_t hitCount() const { return hits_; }

 private:
  tsl::robin_map<uint64_t, uint32_t> index_;
  std::vector<Group> groups_;
  size_t hits_ = 0;
};

/// Delay in seconds of a group or entry: (summed length / count) / c. The one expression every
/// estimator uses, so that a cache with tau = 0 gives path tracing's responses bit for bit.
inline double meanDelaySeconds(float lengthSum, float count, double invSpeedOfSound) {
  return double(lengthSum) / double(count) * invSpeedOfSound;
}

}  // namespace dpc
