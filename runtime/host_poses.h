// HostPoses: what a live host moves, and the one place where a frame's world state is put
// together (docs/design.md "World state"). Hosts publish listener poses, source positions
// and object poses from any thread through seqlock channels (runtime/pose_channel.h); once per
// frame the propagation thread assembles the complete WorldState: every listener where its
// latest pose puts it, then every source and object where its trajectory puts it at the
// played listener's scene time, then the host's overrides on top.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>

#include "runtime/pose_channel.h"
#include "scene/scene.h"
#include "scene/trajectory.h"

namespace dpc {

/// steady_clock now in ns: the time base of ListenerPose::publishedNs and of the session's
/// latency and timing measurements. Any thread; no allocation.
int64_t steadyNowNs() noexcept;

class HostPoses {
 public:
  /// Publishes every listener's pose at scene time 0 (its trajectory's start); `played`
  /// (< scene->listeners.size()) is the listener played first. Control thread; allocates.
  HostPoses(std::shared_ptr<const SceneDesc> scene, size_t played);

  /// Any thread (one writer per listener at a time): listener `index`'s pose (position m,
  /// yaw, pitch and roll radians as dpc::Orientation) for scene time sceneSeconds, timestamped
  /// now. False (nothing changed) for an index out of range, a coordinate outside the
  /// "position" limit (scene/limits.h) or a non-finite angle. Wait-free; no allocation.
  bool setListenerPose(size_t index, const glm::vec3& position, float yawRadians,
                       double sceneSeconds, float pitchRadians, float rollRadians = 0.f);
  /// Any thread (one writer per source at a time): source `index` at `position` (m) instead
  /// of its trajectory from now on. False (nothing changed) for an index out of range or a
  /// coordinate outside the "position" limit. Wait-free; no allocation.
  bool setSourcePosition(size_t index, const glm::vec3& position);
  /// Any thread (one writer per source at a time): source `index` turned by q = (x, y, z, w),
  /// normalised here, instead of its keyframes' rotation from now on (its directivity's
  /// forward axis is R(q) * (+x)). False (nothing changed) for an index out of range or a
  /// zero-length or non-finite rotation. Wait-free; no allocation.
  bool setSourceRotation(size_t index, const float rotation[4]);
  /// Any thread (one writer per object at a time): object `index` at world = R(q) * local +
  /// position, q = (x, y, z, w) normalised here. False (nothing changed) for an index out of
  /// range, a coordinate outside the "position" limit or a zero-length or non-finite rotation.
  /// Wait-free; no allocation.
  bool setObjectPose(size_t index, const glm::vec3& position, const float rotation[4]);
  /// Any thread: source `index` (listener `index`) jumped: its pairs' caches start over at the
  /// next frame (WorldState::sourceTeleports), so its new place is heard at once instead of
  /// averaged with the old one. Call it with (or after) the new pose. False if out of range.
  /// Wait-free; no allocation.
  bool teleportSource(size_t index);
  bool teleportListener(size_t index);
  /// Any thread: plays listener `index` from the next frame on. False if out of range.
  bool select(size_t index);
  size_t played() const { return played_.load(std::memory_order_relaxed); }
  /// Listener `index`'s newest pose in `out`; false (out unchanged) if a write is in progress
  /// or the index is out of range. Any thread, the audio thread too: wait-free, no allocation.
  bool tryListenerPose(size_t index, ListenerPose& out) const {
    return index < scene_->listeners.size() && listeners_[index].tryRead(out);
  }
  size_t listenerCount() const { return scene_->listeners.size(); }

  /// Propagation thread: the complete world state of this frame into `world` (allocates only
  /// while its vectors grow). Returns the played listener's pose (its scene time is the
  /// world's; its publication time measures latency) and its index in `played`.
  ListenerPose assemble(WorldState& world, size_t& played) const;

 private:
  std::shared_ptr<const SceneDesc> scene_;
  std::unique_ptr<PoseChannel[]> listeners_;  ///< one per scene listener
  std::unique_ptr<SeqlockChannel<HostSourcePosition>[]> sources_;
  std::unique_ptr<SeqlockChannel<HostSourceRotation>[]> sourceRotations_;
  std::unique_ptr<SeqlockChannel<HostObjectPose>[]> objects_;
  std::atomic<size_t> played_{0};
  /// Per source, then per listener: a teleport call not yet taken by assemble().
  std::unique_ptr<std::atomic<uint8_t>[]> teleports_;
};

}  // namespace dpc
