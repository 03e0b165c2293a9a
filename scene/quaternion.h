// Rotations as files give them: [x, y, z, w] (glTF order), normalised in double so that a
// rotation typed in a scene's JSON and the same one read from a glTF animation become the same
// float quaternion.
//
// Any thread; no allocation; no errors (a zero-length quaternion gives nullopt).
#pragma once

#include <cmath>
#include <glm/gtc/quaternion.hpp>
#include <optional>

namespace dpc {

/// The unit quaternion along (x, y, z, w), or nullopt when its length is zero or not finite.
/// Any other length is a direction: in double, the squares of floats neither overflow nor
/// vanish, so (0, 1e-20, 0, 1e-20) is the same rotation as (0, 1, 0, 1), as every entry point
/// (files, the C API's pose setters and dpc_yaw_pitch_roll_from_quaternion) reads it.
inline std::optional<glm::quat> unitQuaternion(double x, double y, double z, double w) {
  const double n = std::sqrt(x * x + y * y + z * z + w * w);
  if (!(n > 0.0) || !std::isfinite(n)) return std::nullopt;
  return glm::quat(float(w / n), float(x / n), float(y / n), float(z / n));
}

}  // namespace dpc
