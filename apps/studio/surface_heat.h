// SurfaceHeat: the energy that reaches the listener from each surface, averaged over the frames
// the diffuse path cache keeps, for dpc studio's heat map (docs/studio.md). Each frame brings
// the selected pair's per-surface estimate (Simulation::recordSurfaces: the frame's hit
// intensity over its rays, by the triangle each path reflected from last, 1/m^2 per band
// relative to the source's power); SurfaceHeat keeps its mean over bands (the share of a
// source with equal power per octave band) as an exponential average over K frames, K = the
// DPC's window tau times the frame rate (at least 1: plain path tracing shows each frame).
// The DPC's estimate is a weighted average of its frames' sums, so this is what the cache's
// entries hold, grouped by surface instead of by path.
//
// Control thread (dpc-demo's loop); allocates one float per triangle at construction.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "engine/frame_hits.h"

namespace dpc::studio {

class SurfaceHeat {
 public:
  /// triangles: the geometry's count (the mesh's, then every object's); frames: K above.
  SurfaceHeat(size_t triangles, double frames);
  /// Forgets the average (a new pair was selected: its surfaces are another pair's).
  void reset();
  /// Adds a frame's per-surface estimate; a triangle beyond the count is ignored.
  void add(std::span<const SurfaceTally::Surface> frame);
  /// The triangles holding energy and their averaged energy (1/m^2, band mean), in
  /// triangle order. Allocates the two vectors.
  void nonzero(std::vector<uint32_t>& triangles, std::vector<float>& energy) const;

 private:
  std::vector<float> mean_;
  std::vector<float> frame_;  ///< scratch: this frame's band means per triangle
  double weight_;             ///< 1 / K
  bool empty_ = true;         ///< no frame yet: the first one is taken whole
};

}  // namespace dpc::studio
