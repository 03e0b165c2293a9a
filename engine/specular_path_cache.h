// One source-listener pair's exact specular paths (engine/specular_paths.h), kept across frames.
//
// Persistence across frames (as the DPC keeps its paths, Schissler thesis §3.2.2): each
// source-listener pair keeps the sequences that validated once and re-validates them every
// frame at the current poses; a sequence that is neither valid nor proposed by a ray for
// longer than tau is dropped. Memory is bounded: a frame's candidates and a pair's cache have
// fixed capacities; what does not fit is counted, not stored.
//
// Threads: propagation thread; the caches of different pairs may update concurrently (they only
// read the scene and the tracer). Allocation: as a pair's tables grow toward their capacities.
// No errors.
#pragma once

#include <tsl/robin_map.h>
#include <tsl/robin_set.h>

#include <cstdint>
#include <glm/vec3.hpp>
#include <vector>

#include "engine/specular_paths.h"
#include "scene/directivity.h"

namespace dpc {

/// What a pair's validations depend on besides the sequence and the scene's fixed settings:
/// with equal inputs, SpecularScene::validate gives the same result, bit for bit.
struct SpecularInputs {
  glm::vec3 source{0.f};    ///< metres
  glm::vec3 listener{0.f};  ///< the listener sphere's centre, metres
  float radius = 0.f;       ///< the listener sphere's radius, metres
  /// Changes whenever the object poses do (DirectCache::geometryVersion): the triangles the
  /// paths reflect from and the occluders they pass.
  uint64_t geometry = 0;
  bool operator==(const SpecularInputs&) const = default;
};

/// One source-listener pair's exact paths, kept across frames.
class SpecularPathCache {
 public:
  /// Default capacity of validated sequences per pair (a shoebox has 62 image sources up to
  /// order 3; rooms with many triangles split them into more sequences). At this capacity a
  /// pair would hold about 1.8 MB (entries with their last paths, index, the frame's paths),
  /// and its memo of invalid candidates up to 2 x 16 bytes per candidate of a frame (about
  /// 500 in the dense hall).
  static constexpr size_t kDefaultCapacity = 4096;
  /// Sequences a pair reserves room for at construction (its tables grow from there up to the
  /// capacity): a room's few dozen early paths fit without growing, and 64 pairs do not
  /// commit 64 MB up front.
  static constexpr size_t kInitialReserve = 256;
  /// tauSeconds >= 0: how long a sequence neither valid nor proposed is kept; framePeriod > 0.
  SpecularPathCache(double tauSeconds, double framePeriodSeconds,
                    size_t capacity = kDefaultCapacity);

  /// One frame: re-validates the cached sequences at the current poses, validates this frame's
  /// candidates that are not cached yet, drops expired sequences, and leaves the valid paths in
  /// paths(), sorted by length (then key); coincident duplicates (the same reflection points
  /// through coplanar neighbour triangles) are reported once, under the smaller key.
  /// With the same inputs as the last update (a still pair), a sequence's last result stands:
  /// cached sequences are not validated again, nor the candidates found invalid last frame,
  /// so a still pair validates only the sequences its rays propose for the first time.
  void update(const SpecularCandidates& frame, const SpecularScene& scene,
              const SpecularInputs& inputs, uint64_t frameIndex);

  /// Multiplies every path of the last update by the source's directivity weight toward its
  /// first reflection point P_1 (scene/directivity.h; forward a unit vector, source in metres).
  /// Call after update, only for a directional source. No allocation.
  void weightBySource(const Directivity& directivity, const glm::vec3& forward,
                      const glm::vec3& source);

  const std::vector<SpecularPath>& paths() const { return paths_; }
  /// Keys (SpecularSequence::key) of every sequence valid in the last update(), the coincident
  /// duplicates that paths() reports once included: the sequences whose rays' listener hits an
  /// exact path replaces (FrameHits::groupInto). Also:
  /// - this frame's candidates whose image coincides with a valid path's of the same order
  ///   (the orders round a right-angled corner, floor then wall and wall then floor, mirror
  ///   the source to one image; one of them is valid at the listener's centre, but rays reach
  ///   the sphere by both; at order 1, coplanar faces of different materials): one arrival;
  /// - the sequences refused only because they pass through a gap a few centimetres wide
  ///   (SpecularScene::validate's throughGap): what goes straight through a gap is the slit's
  ///   transmission in the direct sound, which a beam of rays a gap wide, far narrower than
  ///   the first Fresnel zone, would count again.
  const tsl::robin_set<uint64_t>& validKeys() const { return validKeys_; }
  size_t entryCount() const { return entries_.size(); }
  /// Valid sequences not cached because the cache was full, cumulative.
  uint64_t overflow() const { return overflow_; }
  void clear();

 private:
  struct Entry {
    SpecularSequence sequence;
    uint64_t key = 0;
    uint64_t lastAlive = 0;   ///< last frame it was valid or proposed by a ray
    bool valid = false;       ///< its last validation's result, with its path when valid
    bool throughGap = false;  ///< invalid only because it passes through a gap (validate)
    SpecularPath path;
  };
  /// Validates entry e at the inputs, or takes its last result when `still`.
  bool validateEntry(Entry& e, const SpecularScene& scene, const SpecularInputs& in, bool still);
  void revalidate(const SpecularCandidates& frame, const SpecularScene& scene,
                  const SpecularInputs& in, bool still, uint64_t frameIndex);
  void addCandidates(const SpecularCandidates& frame, const SpecularScene& scene,
                     const SpecularInputs& in, bool still, uint64_t frameIndex);
  void removeEntry(size_t i);
  void removeDuplicates();
  /// Adds the candidates' keys whose image is a valid path's to validKeys_ (validKeys()),
  /// every update: the valid paths change as the rays propose sequences, still pair or not.
  void addImageAliases(const SpecularCandidates& frame, const SpecularScene& scene,
                       const SpecularInputs& in);
  /// Whether s's image coincides with one of validImages_ of its order (kSameImageSine).
  bool sameImageAsValid(const SpecularSequence& s, const SpecularScene& scene,
                        const glm::vec3& source) const;

  uint64_t keepFrames_;  ///< tau in frames (rounded down)
  size_t capacity_;
  std::vector<Entry> entries_;
  tsl::robin_map<uint64_t, uint32_t> index_;
  std::vector<SpecularPath> paths_;
  std::vector<uint8_t> dropped_;  ///< scratch for removeDuplicates
  tsl::robin_set<uint64_t> validKeys_;
  struct ValidImage {
    uint32_t order;
    glm::dvec3 image;
    /// Sorted by order, then x (sameImageAsValid searches a range of x).
    static bool before(const ValidImage& a, const ValidImage& b) {
      return a.order != b.order ? a.order < b.order : a.image.x < b.image.x;
    }
  };
  std::vector<ValidImage> validImages_;  ///< scratch for addImageAliases
  /// Candidates found invalid at inputs_ in the last update, and those of this update, each
  /// with 1 when only a gap refused it.
  tsl::robin_map<uint64_t, uint8_t> invalid_, invalidNext_;
  SpecularInputs inputs_;
  bool updated_ = false;  ///< inputs_ holds an update's inputs
  uint64_t overflow_ = 0;
};

}  // namespace dpc
