#include "runtime/host_poses.h"

#include <cassert>
#include <chrono>
#include <cmath>
#include <glm/gtc/quaternion.hpp>
#include <optional>

#include "scene/limits.h"
#include "scene/orientation.h"
#include "scene/quaternion.h"
#include "scene/trajectory.h"

namespace dpc {

int64_t steadyNowNs() noexcept {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

namespace {

/// q / |q| into out (x, y, z, w); false for a zero-length or non-finite q. No allocation.
bool normalisedQuaternion(const float q[4], float out[4]) {
  const std::optional<glm::quat> u = unitQuaternion(q[0], q[1], q[2], q[3]);
  if (!u) return false;
  out[0] = u->x, out[1] = u->y, out[2] = u->z, out[3] = u->w;
  return true;
}

}  // namespace

HostPoses::HostPoses(std::shared_ptr<const SceneDesc> scene, size_t played)
    : scene_(std::move(scene)), played_(played) {
  const SceneDesc& s = *scene_;
  assert(played < s.listeners.size());
  listeners_ = std::make_unique<PoseChannel[]>(s.listeners.size());
  for (size_t l = 0; l < s.listeners.size(); ++l) {
    const Orientation o = listenerOrientationAt(s.listeners[l], 0.0);
    listeners_[l].publish(ListenerPose{listenerPositionAt(s.listeners[l], 0.0), o.yawRadians,
                                       o.pitchRadians, o.rollRadians, steadyNowNs(), 0.0, 0});
  }
  sources_ = std::make_unique<SeqlockChannel<HostSourcePosition>[]>(s.sources.size());
  sourceRotations_ = std::make_unique<SeqlockChannel<HostSourceRotation>[]>(s.sources.size());
  objects_ = std::make_unique<SeqlockChannel<HostObjectPose>[]>(s.objects.size());
  // Value-initialised: every flag 0 (C++20 std::atomic).
  teleports_ = std::make_unique<std::atomic<uint8_t>[]>(s.sources.size() + s.listeners.size());
}

bool HostPoses::setListenerPose(size_t index, const glm::vec3& position, float yawRadians,
                                double sceneSeconds, float pitchRadians, float rollRadians) {
  if (index >= scene_->listeners.size() ||
      !positionWithinLimit(position.x, position.y, position.z) || !std::isfinite(yawRadians) ||
      !std::isfinite(pitchRadians) || !std::isfinite(rollRadians))
    return false;
  // The one writer of this channel reads its own last value: never contended. The interval is
  // a moving average, so that one late or early publication (a host's hiccup, a catch-up)
  // does not read as a change of rate.
  const ListenerPose previous = listeners_[index].read();
  const int64_t now = steadyNowNs();
  const int64_t gap = now - previous.publishedNs;
  const int64_t interval =
      previous.intervalNs > 0 ? previous.intervalNs + (gap - previous.intervalNs) / 4 : gap;
  listeners_[index].publish(
      ListenerPose{position, yawRadians, pitchRadians, rollRadians, now, sceneSeconds, interval});
  return true;
}

bool HostPoses::setSourcePosition(size_t index, const glm::vec3& position) {
  if (index >= scene_->sources.size() || !positionWithinLimit(position.x, position.y, position.z))
    return false;
  sources_[index].publish(HostSourcePosition{position, 1u});
  return true;
}

bool HostPoses::setSourceRotation(size_t index, const float rotation[4]) {
  HostSourceRotation h;
  if (index >= scene_->sources.size() || !normalisedQuaternion(rotation, h.rotation)) return false;
  h.set = 1u;
  sourceRotations_[index].publish(h);
  return true;
}

bool HostPoses::setObjectPose(size_t index, const glm::vec3& position, const float rotation[4]) {
  if (index >= scene_->objects.size() || !positionWithinLimit(position.x, position.y, position.z))
    return false;
  HostObjectPose h;
  if (!normalisedQuaternion(rotation, h.rotation)) return false;
  h.position = position;
  h.set = 1u;
  objects_[index].publish(h);
  return true;
}

bool HostPoses::select(size_t index) {
  if (index >= scene_->listeners.size()) return false;
  played_.store(index, std::memory_order_relaxed);
  return true;
}

bool HostPoses::teleportSource(size_t index) {
  if (index >= scene_->sources.size()) return false;
  teleports_[index].store(1, std::memory_order_relaxed);
  return true;
}

bool HostPoses::teleportListener(size_t index) {
  if (index >= scene_->listeners.size()) return false;
  teleports_[scene_->sources.size() + index].store(1, std::memory_order_relaxed);
  return true;
}

ListenerPose HostPoses::assemble(WorldState& world, size_t& played) const {
  const SceneDesc& s = *scene_;
  played = played_.load(std::memory_order_relaxed);
  ListenerPose pose;
  world.listenerPositions.resize(s.listeners.size());
  world.listenerOrientations.resize(s.listeners.size());
  for (size_t l = 0; l < s.listeners.size(); ++l) {
    const ListenerPose p = listeners_[l].read();
    world.listenerPositions[l] = p.position;
    world.listenerOrientations[l] = Orientation{p.yawRadians, p.pitchRadians, p.rollRadians};
    if (l == played) pose = p;
  }
  // Sources and objects at the played listener's scene time, unless the host placed them.
  const double t = pose.sceneSeconds;
  markTeleports(s, world.timeSeconds, t, world);
  for (size_t i = 0; i < s.sources.size(); ++i)
    if (teleports_[i].exchange(0, std::memory_order_relaxed)) world.sourceTeleports[i] = 1;
  for (size_t l = 0; l < s.listeners.size(); ++l)
    if (teleports_[s.sources.size() + l].exchange(0, std::memory_order_relaxed))
      world.listenerTeleports[l] = 1;
  world.timeSeconds = t;
  world.sourcePositions.resize(s.sources.size());
  for (size_t i = 0; i < s.sources.size(); ++i) {
    const HostSourcePosition h = sources_[i].read();
    world.sourcePositions[i] = h.set ? h.position : sourcePositionAt(s.sources[i], t);
  }
  world.sourceRotations.resize(s.sources.size());
  for (size_t i = 0; i < s.sources.size(); ++i) {
    const HostSourceRotation h = sourceRotations_[i].read();
    world.sourceRotations[i] =
        h.set ? glm::quat(h.rotation[3], h.rotation[0], h.rotation[1], h.rotation[2])
              : sourceRotationAt(s.sources[i], t);
  }
  world.objectPoses.resize(s.objects.size());
  for (size_t k = 0; k < s.objects.size(); ++k) {
    const HostObjectPose h = objects_[k].read();
    world.objectPoses[k] = h.set ? Pose{h.position, glm::quat(h.rotation[3], h.rotation[0],
                                                              h.rotation[1], h.rotation[2])}
                                 : objectPoseAt(s.objects[k], t);
  }
  return pose;
}

}  // namespace dpc
