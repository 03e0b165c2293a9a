#include "scene/orientation.h"

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>

namespace dpc {

glm::vec3 Orientation::forward() const {
  const float cp = std::cos(pitchRadians);
  return {cp * std::cos(yawRadians), std::sin(pitchRadians), -cp * std::sin(yawRadians)};
}

glm::vec3 Orientation::up() const {
  const float sp = std::sin(pitchRadians);
  const glm::vec3 level{-sp * std::cos(yawRadians), std::cos(pitchRadians),
                        sp * std::sin(yawRadians)};
  if (rollRadians == 0.f) return level;
  // Rodrigues about forward (orthogonal to level): the top of the head turns to the right side.
  const glm::vec3 right = glm::cross(forward(), level);
  return std::cos(rollRadians) * level + std::sin(rollRadians) * right;
}

Orientation orientationFromAxes(const glm::vec3& forward, const glm::vec3& up) {
  Orientation o;
  const float horizontal = std::sqrt(forward.x * forward.x + forward.z * forward.z);
  o.yawRadians = horizontal > 0.f ? std::atan2(-forward.z, forward.x) : 0.f;
  o.pitchRadians = std::asin(std::clamp(forward.y, -1.f, 1.f));
  const glm::vec3 level = o.up(), right = glm::cross(o.forward(), level);
  o.rollRadians = std::atan2(glm::dot(up, right), glm::dot(up, level));
  return o;
}

glm::vec3 sourceForward(const glm::quat& q) {
  return q * glm::vec3(1.f, 0.f, 0.f);
}

}  // namespace dpc
