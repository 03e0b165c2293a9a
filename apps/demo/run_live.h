// dpc-demo without --offline: play a scene live through an audio device.
#pragma once

#include "apps/demo/flags.h"
#include "apps/demo/keyboard_motion.h"
#include "runtime/live_session.h"

namespace dpc::demo {

/// Longest --reconnect, seconds: an hour of waiting for a device to come back.
constexpr double kMaxReconnectSeconds = 3600.0;

/// Plays fl.scene live for --duration seconds (or until 'q' with --interactive), the played
/// listener moving along its trajectory or by the keyboard (keyboard_motion.h), a status line
/// on stderr once a second, the summary line on stdout at the end, and --record / --stats
/// files. Main thread (the session runs its propagation thread, the device its audio
/// thread). Returns 0, or kNoAudioDeviceStatus (audio_devices.h) if no device can be opened;
/// throws InputError for bad input and std::exception for anything else.
int runLive(const Flags& fl);

/// Publishes every listener's pose for the next propagation frame: the played one where
/// `motion` puts it, the others on their trajectories at the same scene time (LiveSession's
/// setters, the path of the C API's). Control thread.
void publishPoses(const SceneDesc& scene, const KeyboardMotion& motion, LiveSession& session);

}  // namespace dpc::demo
