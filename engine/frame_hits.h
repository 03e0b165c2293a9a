// FrameHits: one frame's receiver hits of one emitter's trace, in ray order, before they are
// grouped for an estimator (engine/path_cache.h FrameGroups). Each hit is tagged with its exact
// specular sequence when every reflection of its ray so far was specular and there were at
// most exact_order of them (engine/specular_paths.h): such a hit samples that sequence's exact
// path. Grouping happens after the frame's exact paths are known, so whether a hit is left out
// is decided by its own path's identity and this frame's exact paths, never by what a cache
// held the frame before: a hit is left out exactly when the exact path of its sequence is in
// this frame's response (docs/estimators.md, "Exact early specular paths").
//
// Propagation thread (or one tracing worker per object); add and clear allocate only while the
// vectors grow past their high-water mark.
#pragma once

#include <tsl/robin_map.h>
#include <tsl/robin_set.h>

#include <cstdint>
#include <vector>

#include "engine/path_cache.h"

namespace dpc {

/// One frame's hit intensity per surface (the triangle each path reflected from last), summed
/// over the hits an estimator groups, in order of each surface's first hit; 1/m^2 summed over
/// the frame's hits (divide by the rays traced for the frame's estimate, as the energy
/// response is). Propagation thread; grows, then keeps its capacity (clear() keeps it).
class SurfaceTally {
 public:
  struct Surface {
    uint32_t triangle;
    Bands intensity;
  };
  void clear() {
    index_.clear();
    surfaces_.clear();
  }
  void add(uint32_t triangle, const Bands& intensity) {
    const auto [it, added] = index_.try_emplace(triangle, uint32_t(surfaces_.size()));
    if (added) surfaces_.push_back({triangle, Bands(0.f)});
    surfaces_[it->second].intensity += intensity;
  }
  const std::vector<Surface>& surfaces() const { return surfaces_; }
  /// Multiplies every surface's intensity by s (e.g. 1 / rays: the frame's estimate).
  void scale(float s) {
    for (Surface& f : surfaces_) f.intensity *= s;
  }

 private:
  tsl::robin_map<uint32_t, uint32_t> index_;
  std::vector<Surface> surfaces_;
};

class FrameHits {
 public:
  void clear() {
    hits_.clear();
    sequence_.clear();
    exact_.clear();
  }
  /// Appends a hit; exact: its ray's reflections so far are an exact specular sequence, whose
  /// key (SpecularSequence::key, source-first) is `sequence`.
  void add(const PathHit& hit, bool exact, uint64_t sequence) {
    hits_.push_back(hit);
    exact_.push_back(exact ? 1 : 0);
    sequence_.push_back(sequence);
  }
  size_t size() const { return hits_.size(); }
  const PathHit& hit(size_t i) const { return hits_[i]; }
  bool exact(size_t i) const { return exact_[i] != 0; }
  uint64_t sequence(size_t i) const { return sequence_[i]; }

  /// Adds, in ray order, every hit to `groups` except those an exact path replaces: an exact
  /// specular hit whose sequence is in `exactPaths` (the pair's SpecularPathCache::validKeys
  /// of this frame), or every exact specular hit when exactPaths is null. With `surfaces`,
  /// also adds each hit grouped to its surface's tally (SurfaceTally). Returns the hits left
  /// out.
  size_t groupInto(FrameGroups& groups, const tsl::robin_set<uint64_t>* exactPaths,
                   SurfaceTally* surfaces = nullptr) const {
    size_t replaced = 0;
    for (size_t i = 0; i < hits_.size(); ++i) {
      if (exact_[i] && (!exactPaths || exactPaths->contains(sequence_[i]))) {
        ++replaced;
        continue;
      }
      groups.add(hits_[i]);
      if (surfaces && hits_[i].surface != PathHit::kNoSurface)
        surfaces->add(hits_[i].surface, hits_[i].intensity);
    }
    return replaced;
  }

 private:
  std::vector<PathHit> hits_;
  std::vector<uint64_t> sequence_;
  std::vector<uint8_t> exact_;
};

}  // namespace dpc
