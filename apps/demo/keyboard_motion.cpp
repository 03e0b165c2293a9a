// The live run's listener motion: trajectory on a wall clock, or the keyboard.
#include "apps/demo/keyboard_motion.h"

#include <cmath>
#include <numbers>

#include "apps/demo/terminal.h"
#include "scene/orientation.h"
#include "scene/trajectory.h"

namespace dpc::demo {
namespace {

constexpr float kStepMetres = 0.25f;
constexpr float kTurnRadians = float(std::numbers::pi / 12);

}  // namespace

KeyboardMotion::KeyboardMotion(const SceneDesc& scene, size_t playedIndex)
    : scene_(scene),
      played_(&scene.listeners.at(playedIndex)),
      playedIndex_(playedIndex),
      position_(listenerPositionAt(*played_, 0.0)),
      yaw_(listenerOrientationAt(*played_, 0.0).yawRadians) {}

void KeyboardMotion::move(float forwardSteps, float rightSteps) {
  const glm::vec3 forward(std::cos(yaw_), 0.f, -std::sin(yaw_));
  const glm::vec3 right(std::sin(yaw_), 0.f, std::cos(yaw_));
  position_ += forward * (forwardSteps * kStepMetres) + right * (rightSteps * kStepMetres);
  manual_ = true;
}

KeyboardMotion::Action KeyboardMotion::key(int k) {
  switch (k) {
    case 'q':
      return Action::kQuit;
    case ' ':
      paused_ = !paused_;
      return Action::kNone;
    case 'l':
      playedIndex_ = (playedIndex_ + 1) % scene_.listeners.size();
      played_ = &scene_.listeners[playedIndex_];
      position_ = listenerPositionAt(*played_, sceneTime_);
      manual_ = false;
      return Action::kNextListener;
    case 'w':
    case kKeyUp:
      move(1.f, 0.f);
      break;
    case 's':
    case kKeyDown:
      move(-1.f, 0.f);
      break;
    case 'a':
    case kKeyLeft:
      move(0.f, -1.f);
      break;
    case 'd':
    case kKeyRight:
      move(0.f, 1.f);
      break;
    case 'Q':  // turn left
      yawOffset_ += kTurnRadians;
      break;
    case 'E':  // turn right
    case 'e':
      yawOffset_ -= kTurnRadians;
      break;
  }
  return Action::kNone;
}

void KeyboardMotion::place(const glm::vec3& position, float yawRadians) {
  position_ = position;
  // advance() adds the trajectory's heading: keep the offset that gives the yaw asked for.
  yawOffset_ = yawRadians - listenerOrientationAt(*played_, sceneTime_).yawRadians;
  yaw_ = yawRadians;
  manual_ = true;
}

void KeyboardMotion::advance(double dtSeconds) {
  if (!paused_ && !manual_) {
    sceneTime_ += dtSeconds;
    position_ = listenerPositionAt(*played_, sceneTime_);
  }
  const Orientation heading = listenerOrientationAt(*played_, sceneTime_);
  yaw_ = heading.yawRadians + yawOffset_;
  pitch_ = heading.pitchRadians;
  roll_ = heading.rollRadians;
}

}  // namespace dpc::demo
