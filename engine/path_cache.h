// Estimators that turn one frame's listener hits into an energy response: plain Monte Carlo
// path tracing and the diffuse path cache (DPC) of Schissler's thesis, section 3.2.2.
//
// Both see the frame's hits grouped by path identifier (FrameGroups, in first-hit order).
// - PathTracingEstimator: every group adds I_f / N at delay (r_f / eta_f) / c, nothing is
//   kept between frames.
// - DiffusePathCache: entries (eta, mu, I_hat, r_hat, created) persist across frames.
//   Weighting kSeed is the thesis: eq. 3.4 update, eq. 3.2 I_bar = I_hat / mu, eq. 3.3
//   r_bar = r_hat / eta, removal after tau. Weighting kEma is dpc's unbiased variant: each
//   entry keeps an exponential moving average (time constant tau) of its per-frame estimate
//   I_f / N, decayed every frame whether hit or not, normalised by 1 - (1-a)^(n+1) for the
//   n+1 frames since the cache started, and dropped once its weight falls below
//   kEmaDropFraction (docs/estimators.md has the derivation and the measurements).
//   Weighting kWindow: each entry holds the sums of its per-frame estimates over the last
//   W = round(tau / T) frames (at least 1) and reads out their mean, sum / min(frames so far,
//   W); each frame's contributions are kept in a ring of W frames and subtracted when they
//   leave the window; an entry with no hit left in the window is removed. Unbiased for a
//   static scene, and a step is answered completely W frames later.
// With tau = 0 every weighting reduce to PathTracingEstimator, bit for bit (the same float
// operations in the same order); tests/engine/path_cache_test.cpp checks it.
// Propagation thread only. Allocation: tables grow as needed (amortised), then keep their
// capacity. No errors.
#pragma once

#include <tsl/robin_map.h>

#include <cstdint>
#include <glm/vec3.hpp>
#include <span>
#include <vector>

#include "engine/bands.h"
#include "engine/energy_response.h"
#include "engine/scene.h"

namespace dpc {

/// One ray segment that crossed the listener sphere.
struct PathHit {
  uint64_t key = 0;          ///< path identifier hash K (engine/patch.h)
  Bands intensity{0.f};      ///< I(omega) = band energy * air attenuation / (pi R^2), 1/m^2
  float length = 0.f;        ///< r, path length to the listener, metres
  glm::vec3 direction{0.f};  ///< unit vector from the listener toward the arriving sound
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

/// Plain Monte Carlo path tracing: no memory between frames.
/// Delay in seconds of a group or entry: (summed length / count) / c. The one expression both
/// estimators use, so that tau = 0 gives bit-identical responses.
inline double meanDelaySeconds(float lengthSum, float count, double invSpeedOfSound) {
  return double(lengthSum) / double(count) * invSpeedOfSound;
}

class PathTracingEstimator {
 public:
  /// Adds every group's I_f / N at delay (r_f / eta_f) / c to out. N = rays emitted this frame.
  /// directional (optional): also receives every contribution with its arrival direction.
  void endFrame(const FrameGroups& frame, uint64_t raysEmitted, float speedOfSound,
                EnergyResponse& out, DirectionalEnergyResponse* directional = nullptr) const;
};

class DiffusePathCache {
 public:
  /// Weight below which an EMA entry that is no longer hit is dropped (bias <= this fraction
  /// of one hit's contribution).
  static constexpr double kEmaDropFraction = 1e-3;

  /// Heap bytes one entry costs: the 64-byte Entry plus its index bucket (24 bytes) at the
  /// index's 0.8 load factor.
  static constexpr size_t kBytesPerEntry = 64 + 30;
  /// Default memory budget per cache (one cache per source-listener pair), megabytes.
  static constexpr double kDefaultBudgetMb = 64.0;
  /// Entries (path entries plus coarse entries) that fit a budget of megabytes (>= 1 entry).
  static size_t entriesForBudget(double megabytes);
  static constexpr size_t kDefaultMaxEntries =
      size_t(kDefaultBudgetMb * 1048576.0) / kBytesPerEntry;
  /// Width of a coarse-store delay bin, seconds.
  static constexpr double kCoarseBinSeconds = 1e-3;

  /// tauSeconds >= 0: cache response time; framePeriodSeconds > 0. maxEntries > 0: after a
  /// frame, while path entries plus coarse entries exceed the cap, the oldest path entries (by
  /// creation for kSeed, by last hit for kEma) are merged into the coarse store instead of
  /// dropped: one coarse entry per 1 ms delay bin (and, for kSeed, per creation frame), whose
  /// state is the sum of the merged entries' states. Both weightings' readouts are linear in
  /// the state, so the response's energy is unchanged by a merge (within float rounding); the
  /// cost is the delay resolution (1 ms bins, hit-weighted mean delay) and the arrival
  /// direction (intensity-weighted mean). Coarse entries are read out and expire like path
  /// entries (EMA: by the newest merged entry's last hit). docs/estimators.md.
  DiffusePathCache(DpcWeighting weighting, double tauSeconds, double framePeriodSeconds,
                   size_t maxEntries = kDefaultMaxEntries);

  /// One frame: applies the frame's groups (eq. 3.4), then mu += N for every entry and adds
  /// every entry's estimate (eq. 3.2, 3.3, or the EMA) to out, then removes expired entries.
  /// directional (optional): also receives every entry's estimate with its mean arrival
  /// direction (intensity-weighted over the entry's hits).
  void endFrame(const FrameGroups& frame, uint64_t raysEmitted, float speedOfSound,
                EnergyResponse& out, DirectionalEnergyResponse* directional = nullptr);

  void clear();
  /// Path entries (coarse entries not included).
  size_t entryCount() const { return entries_.size(); }
  /// Coarse-store entries (merged evicted path entries).
  size_t coarseEntryCount() const { return coarse_.size(); }
  /// Cap on path entries plus coarse entries.
  size_t maxEntries() const { return maxEntries_; }
  /// Heap bytes held by the cache's tables (entries and index).
  size_t bytes() const;
  /// Frames an entry is read out: seed = after its creation; EMA = after its last hit;
  /// window = the window length W.
  uint32_t lifetimeFrames() const { return lifetime_; }
  /// EMA coefficient a = 1 - exp(-T / tau) (1 when tau = 0).
  double emaCoefficient() const { return a_; }

  /// 64 bytes. mu (rays emitted while the entry existed) is not stored: it is the rays
  /// emitted since the entry's creation frame, kept per frame in a small ring.
  struct Entry {
    uint64_t key;
    uint32_t stamp;       ///< seed: frame created; EMA: frame last hit
    float eta;            ///< seed: rays of this path that reached the listener (exact to 2^24);
                          ///< EMA: moving average of eta_f
    Bands intensity;      ///< seed: I_hat (sum); EMA: moving average of I_f / N
    float length;         ///< seed: r_hat (sum); EMA: moving average of r_f
    glm::vec3 direction;  ///< summed / averaged arrival direction (intensity weighted)
  };
  static_assert(sizeof(Entry) == 64);
  /// Path entries merged into the coarse store by the cap since construction (none lost).
  uint64_t mergedEntries() const { return merged_; }
  /// Fraction of the last frame's response energy (band average) read out from the coarse
  /// store, in [0, 1].
  double coarseEnergyFraction() const { return coarseFraction_; }
  const std::vector<Entry>& entries() const { return entries_; }

 private:
  /// One frame's contribution to one entry, kept for the sliding window.
  struct WindowTerm {
    uint64_t key;
    Bands intensity;  ///< I_f / N
    float length;     ///< r_f summed
    float eta;        ///< hits this frame
    glm::vec3 direction;
  };
  /// kWindow: a path entry merged into the coarse store: which coarse entry, and the last frame
  /// whose terms went there (terms of later frames belong to a path entry again).
  struct MergeRecord {
    uint64_t coarseKey;
    uint32_t frame;
  };
  /// kWindow: retires the frame leaving the window, adds this frame's groups, reads out (adds
  /// the band-average energy read out to total, and the coarse store's share to coarse).
  void windowEndFrame(const FrameGroups& frame, float n, double invC, EnergyResponse& out,
                      DirectionalEnergyResponse* directional, double& total, double& coarse);
  void removeCoarseAt(size_t i);

  size_t windowBytes() const;
  Entry* findOrInsert(uint64_t key, bool& inserted);
  void removeAt(size_t i);
  void mergeIntoCoarse(const Entry& e, double invSpeedOfSound);

  DpcWeighting weighting_;
  double a_ = 1.0;
  uint32_t lifetime_ = 1;
  uint32_t frame_ = 0;     ///< frames since the cache started (or was cleared)
  double decayPow_ = 1.0;  ///< (1-a)^(frame_+1), for the start-up normalisation
  size_t maxEntries_;
  uint64_t merged_ = 0;
  double coarseFraction_ = 0.0;
  tsl::robin_map<uint64_t, uint32_t> coarseIndex_;  ///< coarse key -> index in coarse_
  std::vector<Entry> coarse_;
  uint64_t raysTotal_ = 0;            ///< rays emitted since the start, this frame included
  std::vector<uint64_t> raysBefore_;  ///< ring: rays emitted before frame f, f % size
  std::vector<std::pair<uint32_t, uint32_t>> scratch_;  ///< (stamp, index) for the cap
  std::vector<uint64_t> dropKeys_;
  std::vector<std::vector<WindowTerm>> window_;  ///< kWindow: ring of the last W frames' terms
  tsl::robin_map<uint64_t, MergeRecord> mergedAt_;  ///< kWindow: path key -> its merge
  tsl::robin_map<uint64_t, uint32_t> index_;
  std::vector<Entry> entries_;
};

}  // namespace dpc
