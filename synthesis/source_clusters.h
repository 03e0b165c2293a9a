// Clusters of sources that share a late reverberation bus (hybrid rendering,
// synthesis/hybrid_split.h), recomputed every frame for one listener.
//
// Criteria (Schissler & Manocha, ACM TOG 36(1) 2016, section 6.1): sources join a cluster when
// they lie close together in direction as seen from the listener (the cluster's angular radius,
// member to mean direction, stays within maxAngleRadians) and can see each other (a member and
// the cluster's seed, its first member, are mutually visible: sources in another room, whose
// reverberation differs, do not share a bus). The number of clusters is bounded by the late
// buses; when a source fits no cluster and no bus is free it joins a cluster anyway (counted:
// forcedJoins()): the one it joined so last frame while that still exists, else the one nearest
// in direction. Such a member does not move its cluster's mean direction, so the members that
// fit are judged as if it were not there, and it is placed anew every frame (a bus may have
// come free, or a cluster come within the bound) but stays where it was when nothing changed.
//
// Hysteresis: a source stays in its previous cluster while it is within (1 + hysteresis) of the
// angular bound and still sees the seed; only otherwise is it assigned anew, so sources near
// a boundary do not flicker between buses from frame to frame (switches() counts the moves).
//
// Threads: the propagation thread. Construction allocates; update() does not. No errors.
#pragma once

#include <cstdint>
#include <functional>
#include <glm/vec3.hpp>
#include <span>
#include <vector>

namespace dpc {

class SourceClusters {
 public:
  /// Whether the straight path between two points (metres) is free.
  using Visible = std::function<bool(const glm::vec3&, const glm::vec3&)>;
  static constexpr int kNone = -1;

  /// sources >= 1, buses >= 1; maxAngleRadians in (0, pi]; hysteresis >= 0 (0.25: a member
  /// leaves at 1.25 times the angle that lets a source join).
  SourceClusters(size_t sources, int buses, double maxAngleRadians, double hysteresis = 0.25);

  /// Assigns every source to a cluster for a listener at `listener` (metres, world) and the
  /// sources at `sources` (one per source). `active[s]` false keeps source s out of every
  /// cluster (cluster(s) == kNone; empty span: all active).
  void update(const glm::vec3& listener, std::span<const glm::vec3> sources,
              const Visible& visible, std::span<const bool> active = {});

  /// Source s's cluster in 0 .. buses - 1, or kNone.
  int cluster(size_t s) const { return assignment_[s]; }
  int buses() const { return int(seed_.size()); }
  /// Clusters with at least one member after the last update.
  int occupied() const;
  /// Largest angle (radians) between a member's direction and its cluster's mean direction,
  /// over all clusters' members that fit (not those joined for want of a bus), after the last
  /// update.
  double maxAngularRadius() const { return maxRadius_; }
  /// Sources that changed cluster (between two updates where they were in one), in total.
  uint64_t switches() const { return switches_; }
  /// Sources that joined a cluster beyond the angular bound or unseen, for want of a free bus.
  uint64_t forcedJoins() const { return forcedJoins_; }

 private:
  /// Mean direction of each cluster's members (the previous assignment, current positions).
  void computeMeans();
  /// Best cluster for source s that satisfies the criteria, or kNone.
  int bestFit(size_t s, std::span<const glm::vec3> sources, const Visible& visible) const;
  /// Keeps s in its cluster if the hysteresis allows.
  bool stays(size_t s, std::span<const glm::vec3> sources, const Visible& visible) const;
  /// Clears the assignment, keeping the seeds that stay (each then its cluster's first member).
  void keepSeeds(size_t n, std::span<const glm::vec3> sources, const Visible& visible,
                 std::span<const bool> active);
  /// switches_ and maxRadius_ after an assignment.
  void countMoves(size_t n);
  /// Puts s in cluster k; `forced`: beyond the criteria, for want of a bus (above).
  void assign(size_t s, int k, bool forced = false);
  int freeBus() const;
  int nearestMean(size_t s) const;
  /// The cluster s joins for want of a bus: its previous one if it still exists, else the
  /// nearest in direction.
  int forcedCluster(size_t s) const;

  double maxAngle_, hysteresis_;
  std::vector<int> assignment_, previous_;
  std::vector<char> forced_;          ///< per source: joined its cluster for want of a bus
  std::vector<int> seed_;             ///< per cluster: its first member, or kNone
  std::vector<glm::vec3> sum_;        ///< per cluster: sum of member directions
  std::vector<glm::vec3> mean_;       ///< per cluster: normalised sum_ (previous members)
  std::vector<glm::vec3> direction_;  ///< per source: unit vector listener -> source
  double maxRadius_ = 0.0;
  uint64_t switches_ = 0, forcedJoins_ = 0;
};

}  // namespace dpc
