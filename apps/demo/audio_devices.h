// dpc-demo's audio devices: --list-devices, and opening the output of a live run.
#pragma once

#include <memory>
#include <string>

#include "apps/demo/flags.h"
#include "audio/audio_output.h"
#include "runtime/live_session.h"

namespace dpc::demo {

/// Exit status of a live run whose audio output cannot be opened.
constexpr int kNoAudioDeviceStatus = 3;

/// --list-devices: one line per PortAudio output device on stdout (the default marked "*"),
/// or how to get one when there is none. Main thread. Returns 0; throws std::runtime_error if
/// PortAudio cannot be initialised.
int listDevices();

/// Channels a live run plays: renderedChannels(), except 2 (the same signal, "left" and
/// "right") for mono, which both loudspeakers of a stereo device play. Any thread.
int deviceChannels(const AudioSettings& audio);

/// Opens --device for the scene's output (deviceChannels() channels named as
/// renderedChannelNames(); Ambisonic channels are not connected to loudspeakers), at the
/// scene's rate and block size, not started. Its callback renders `*session`, which must be
/// set before the output is started. On failure prints one line "dpc-demo: why; the way
/// out" on stderr and returns null. Main thread. Allocates.
std::unique_ptr<audio::AudioOutput> openOutput(const SceneDesc& scene, const Flags& fl,
                                               std::unique_ptr<LiveSession>* session);
/// openOutput() without the message: on failure returns null and sets `why` to the device
/// layer's one-line reason (a reconnection attempt's). Main thread. Allocates.
std::unique_ptr<audio::AudioOutput> tryOpenOutput(const SceneDesc& scene, const Flags& fl,
                                                  std::unique_ptr<LiveSession>* session,
                                                  std::string& why);

}  // namespace dpc::demo
