// Orientations in the scene's frame (right-handed, y up): a listener's yaw, pitch and roll
// (Orientation) and its world axes, and the forward axis of a source's directivity at a
// rotation. Plain values and pure functions.
//
// Threads: any thread. Allocation: none. Errors: none.
#pragma once

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

namespace dpc {

/// Listener orientation: heading (yaw, about +y, 0 = facing +x, positive = turning left),
/// pitch (above the horizon) and roll (about forward, positive = the right ear down), radians,
/// applied in that order. forward() and up() are world unit vectors (y up); roll turns up()
/// about forward() and leaves forward() as it is.
struct Orientation {
  float yawRadians = 0.f;
  float pitchRadians = 0.f;
  float rollRadians = 0.f;
  glm::vec3 forward() const;
  glm::vec3 up() const;
};

/// The yaw, pitch and roll (radians) of the orientation whose forward and up are these world
/// directions (unit, orthogonal): the inverse of Orientation::forward()/up(). Straight up or
/// down the yaw is undetermined: 0, with the tilt in roll. Any thread; no allocation.
Orientation orientationFromAxes(const glm::vec3& forward, const glm::vec3& up);

/// The unit forward axis of a source's directivity at rotation q (unit quaternion): q * (+x).
glm::vec3 sourceForward(const glm::quat& q);

}  // namespace dpc
