#include "scene/trajectory.h"

#include <algorithm>
#include <cmath>

namespace dpc {

namespace {

/// Position along keyframes (linear; clamped, or wrapped when loop is set).
glm::vec3 positionAlong(const std::vector<Keyframe>& k, bool loop, const glm::vec3& fixed,
                        double t) {
  if (k.empty()) return fixed;
  if (k.size() == 1 || !std::isfinite(t)) return k.front().position;
  const double t0 = k.front().timeSeconds, t1 = k.back().timeSeconds;
  if (loop) {
    const double period = t1 - t0;
    t = t0 + (t - t0) - period * std::floor((t - t0) / period);  // into [t0, t1)
  }
  if (t <= t0) return k.front().position;
  if (t >= t1) return k.back().position;
  // First keyframe with time > t; t lies in [prev.time, next.time).
  const auto next = std::upper_bound(
      k.begin(), k.end(), t, [](double x, const Keyframe& key) { return x < key.timeSeconds; });
  const auto prev = next - 1;
  if (next->teleport) return prev->position;  // held until the jump
  const double u = (t - prev->timeSeconds) / (next->timeSeconds - prev->timeSeconds);
  return prev->position + float(u) * (next->position - prev->position);
}

/// Slerp from a to b by u along the shorter arc (q and -q are the same rotation), normalised.
glm::quat slerpShorter(const glm::quat& a, glm::quat b, float u) {
  if (glm::dot(a, b) < 0.f) b = -b;
  return glm::normalize(glm::slerp(a, b, u));
}

}  // namespace

glm::vec3 listenerPositionAt(const ListenerDesc& listener, double t) {
  return positionAlong(listener.trajectory, listener.loop, listener.position, t);
}

glm::vec3 sourcePositionAt(const SourceDesc& source, double t) {
  return positionAlong(source.trajectory, source.trajectoryLoop, source.position, t);
}

Pose objectPoseAt(const ObjectDesc& object, double t) {
  const auto& k = object.trajectory;
  if (k.empty()) return {};
  if (k.size() == 1 || !std::isfinite(t)) return {k.front().position, k.front().rotation};
  const double t0 = k.front().timeSeconds, t1 = k.back().timeSeconds;
  if (object.loop) t = t0 + (t - t0) - (t1 - t0) * std::floor((t - t0) / (t1 - t0));
  if (t <= t0) return {k.front().position, k.front().rotation};
  if (t >= t1) return {k.back().position, k.back().rotation};
  const auto next =
      std::upper_bound(k.begin(), k.end(), t,
                       [](double x, const ObjectKeyframe& key) { return x < key.timeSeconds; });
  const auto prev = next - 1;
  const float u = float((t - prev->timeSeconds) / (next->timeSeconds - prev->timeSeconds));
  Pose p;
  p.position = prev->position + u * (next->position - prev->position);
  p.rotation = slerpShorter(prev->rotation, next->rotation, u);
  return p;
}

glm::quat sourceRotationAt(const SourceDesc& source, double t) {
  const auto& k = source.trajectory;
  if (k.empty() || !k.front().rotation) return source.rotation;
  if (k.size() == 1 || !std::isfinite(t)) return *k.front().rotation;
  const double t0 = k.front().timeSeconds, t1 = k.back().timeSeconds;
  if (source.trajectoryLoop) t = t0 + (t - t0) - (t1 - t0) * std::floor((t - t0) / (t1 - t0));
  if (t <= t0) return *k.front().rotation;
  if (t >= t1) return *k.back().rotation;
  const auto next = std::upper_bound(
      k.begin(), k.end(), t, [](double x, const Keyframe& key) { return x < key.timeSeconds; });
  const auto prev = next - 1;
  // A keyframe without a rotation (only when the scene was built in code): the source's.
  const glm::quat a = prev->rotation.value_or(source.rotation);
  const glm::quat b = next->rotation.value_or(source.rotation);
  return slerpShorter(a, b,
                      float((t - prev->timeSeconds) / (next->timeSeconds - prev->timeSeconds)));
}


bool teleportBetween(const std::vector<Keyframe>& keys, bool loop, double from, double to) {
  if (!(to > from) || keys.size() < 2) return false;
  const double t0 = keys.front().timeSeconds, period = keys.back().timeSeconds - t0;
  for (const Keyframe& k : keys) {
    if (!k.teleport) continue;
    if (!loop || !(period > 0.0)) {
      if (k.timeSeconds > from && k.timeSeconds <= to) return true;
      continue;
    }
    // The latest repetition of k at or before `to`, k + n * period with n >= 0.
    const double n = std::floor((to - k.timeSeconds) / period);
    if (n >= 0.0 && k.timeSeconds + n * period > from) return true;
  }
  return false;
}

void markTeleports(const SceneDesc& scene, double from, double to, WorldState& world) {
  world.sourceTeleports.resize(scene.sources.size());
  for (size_t i = 0; i < scene.sources.size(); ++i)
    world.sourceTeleports[i] =
        teleportBetween(scene.sources[i].trajectory, scene.sources[i].trajectoryLoop, from, to);
  world.listenerTeleports.resize(scene.listeners.size());
  for (size_t i = 0; i < scene.listeners.size(); ++i)
    world.listenerTeleports[i] =
        teleportBetween(scene.listeners[i].trajectory, scene.listeners[i].loop, from, to);
}

void evaluateWorld(const SceneDesc& scene, double t, WorldState& state) {
  markTeleports(scene, state.timeSeconds, t, state);
  state.timeSeconds = t;
  state.listenerPositions.resize(scene.listeners.size());
  state.listenerOrientations.resize(scene.listeners.size());
  for (size_t i = 0; i < scene.listeners.size(); ++i) {
    state.listenerPositions[i] = listenerPositionAt(scene.listeners[i], t);
    state.listenerOrientations[i] = listenerOrientationAt(scene.listeners[i], t);
  }
  state.sourcePositions.resize(scene.sources.size());
  for (size_t i = 0; i < scene.sources.size(); ++i)
    state.sourcePositions[i] = sourcePositionAt(scene.sources[i], t);
  state.sourceRotations.resize(scene.sources.size());
  for (size_t i = 0; i < scene.sources.size(); ++i)
    state.sourceRotations[i] = sourceRotationAt(scene.sources[i], t);
  state.objectPoses.resize(scene.objects.size());
  for (size_t i = 0; i < scene.objects.size(); ++i)
    state.objectPoses[i] = objectPoseAt(scene.objects[i], t);
}

Orientation listenerOrientationAt(const ListenerDesc& listener, double t) {
  constexpr float kDeg = float(3.14159265358979323846 / 180.0);
  Orientation o;
  o.yawRadians = listener.yawDegrees * kDeg;
  o.pitchRadians = listener.pitchDegrees * kDeg;
  o.rollRadians = listener.rollDegrees * kDeg;
  const auto& k = listener.trajectory;
  if (k.empty()) return o;
  if (listener.loop && k.size() > 1) {
    const double t0 = k.front().timeSeconds, period = k.back().timeSeconds - t0;
    t = t0 + (t - t0) - period * std::floor((t - t0) / period);
  }
  // Segment [i, i+1] holding t (clamped to the ends).
  size_t i = 0;
  while (i + 2 < k.size() && t >= k[i + 1].timeSeconds) ++i;
  if (k.front().yawDegrees) {
    if (k.size() == 1 || t <= k.front().timeSeconds) {
      o.yawRadians = *k.front().yawDegrees * kDeg;
      o.pitchRadians = k.front().pitchDegrees.value_or(0.f) * kDeg;
      o.rollRadians = k.front().rollDegrees.value_or(0.f) * kDeg;
      return o;
    }
    const Keyframe &a = k[i], &b = k[i + 1];
    const float u =
        float(std::clamp((t - a.timeSeconds) / (b.timeSeconds - a.timeSeconds), 0.0, 1.0));
    const float dy = std::remainder(*b.yawDegrees - *a.yawDegrees, 360.f);  // shorter arc
    o.yawRadians = (*a.yawDegrees + u * dy) * kDeg;
    auto lerp = [u](const std::optional<float>& x, const std::optional<float>& y) {
      return x.value_or(0.f) + u * (y.value_or(0.f) - x.value_or(0.f));
    };
    o.pitchRadians = lerp(a.pitchDegrees, b.pitchDegrees) * kDeg;
    o.rollRadians = lerp(a.rollDegrees, b.rollDegrees) * kDeg;
    return o;
  }
  // Face the walking direction: this segment's, or the last moving segment's before it.
  for (size_t j = i + 1; j-- > 0;) {
    if (j + 1 >= k.size()) continue;
    const glm::vec3 v = k[j + 1].position - k[j].position;
    if (v.x * v.x + v.z * v.z > 1e-12f) {
      o.yawRadians = std::atan2(-v.z, v.x);
      return o;
    }
  }
  return o;
}

}  // namespace dpc
