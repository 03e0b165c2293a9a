// How dpc-demo moves the played listener in a live run: along its trajectory on a wall
// clock, or by the keyboard (--interactive).
#pragma once

#include <cstddef>
#include <glm/vec3.hpp>

#include "scene/scene.h"

namespace dpc::demo {

/// The played listener's pose in a live run. The trajectory runs on scene time, which
/// advances with the wall clock unless paused (space) or taken over by the keyboard (a move
/// key: the listener then stays where the keys put it). Q/E turn the head relative to the
/// trajectory's heading; 'l' plays the scene's next listener (following its trajectory
/// again). Orientation convention of scene/orientation.h: forward = (cos yaw, 0, -sin yaw).
/// Main thread only. No allocation. `scene` must outlive the object.
class KeyboardMotion {
 public:
  /// What a key asks of the caller beyond the pose.
  enum class Action { kNone, kQuit, kNextListener };

  /// Starts at scene time 0 on scene.listeners[playedIndex] (std::out_of_range if there is
  /// none).
  KeyboardMotion(const SceneDesc& scene, size_t playedIndex);

  /// Applies one key (terminal.h codes): arrows/WASD move 0.25 m, Q/E turn 15 degrees,
  /// space pauses, 'l' next listener (kNextListener), 'q' quits (kQuit); others do nothing.
  Action key(int k);
  /// Puts the played listener at `position` facing `yawRadians` (dpc studio's drag): like a
  /// move key, the listener then stays where it was put while scene time stands still.
  void place(const glm::vec3& position, float yawRadians);
  /// Advances scene time by dtSeconds (unless paused or moved by the keyboard) and
  /// updates the pose from the played listener's trajectory.
  void advance(double dtSeconds);

  const ListenerDesc& played() const { return *played_; }
  size_t playedIndex() const { return playedIndex_; }
  double sceneTime() const { return sceneTime_; }
  const glm::vec3& position() const { return position_; }
  /// Heading of the trajectory plus the keyboard's turn, radians.
  float yaw() const { return yaw_; }
  /// Pitch of the trajectory, radians.
  float pitch() const { return pitch_; }
  float roll() const { return roll_; }

 private:
  /// Moves `steps` (+1 forward/right, -1 back/left) along the current heading.
  void move(float forwardSteps, float rightSteps);

  const SceneDesc& scene_;
  const ListenerDesc* played_;
  size_t playedIndex_;
  double sceneTime_ = 0.0;
  bool paused_ = false, manual_ = false;
  glm::vec3 position_;
  float yawOffset_ = 0.f;
  float yaw_, pitch_ = 0.f, roll_ = 0.f;
};

}  // namespace dpc::demo
