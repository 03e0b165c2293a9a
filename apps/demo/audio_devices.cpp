// PortAudio devices as dpc-demo lists and opens them.
#include "apps/demo/audio_devices.h"

#include <cstdio>
#include <string>

#include "audio/portaudio_backend.h"
#include "runtime/output_format.h"

namespace dpc::demo {

int listDevices() {
  const auto devices = audio::listOutputDevices();
  if (devices.empty()) {
    std::printf(
        "no audio output devices (start a JACK server, e.g. jackd -d dummy -r 48000 "
        "-p 128, or render with --offline OUT.wav)\n");
    return 0;
  }
  for (const auto& d : devices)
    std::printf("%s%-40s  %-28s  %d ch  %.0f Hz  %.1f ms\n", d.isDefault ? "* " : "  ",
                d.spec().c_str(), d.hostApi.c_str(), d.maxOutputChannels, d.defaultSampleRate,
                d.defaultLowOutputLatency * 1e3);
  return 0;
}

namespace {

/// The device's callback: the session that `user` (a std::unique_ptr<LiveSession>*)
/// holds by the time the device starts. Audio thread (LiveSession::render asserts it).
void renderSession(void* user, float* const* out, int frames) noexcept {
  (*static_cast<std::unique_ptr<LiveSession>*>(user))->render(nullptr, out, frames);
}

}  // namespace

int deviceChannels(const AudioSettings& audio) {
  return audio.output == OutputFormat::kMono ? 2 : renderedChannels(audio);
}

std::unique_ptr<audio::AudioOutput> tryOpenOutput(const SceneDesc& scene, const Flags& fl,
                                                  std::unique_ptr<LiveSession>* session,
                                                  std::string& why) {
  audio::AudioOutput::Options ao;
  ao.device = fl.device;
  ao.sampleRate = scene.audio.sampleRate;
  ao.channels = deviceChannels(scene.audio);
  ao.blockSize = scene.audio.blockSize;
  if (scene.audio.output == OutputFormat::kMono)
    ao.channelNames = {"left", "right"};
  else
    ao.channelNames = renderedChannelNames(scene.audio);
  ao.clientName = "dpc-demo";
  ao.connectPhysical = scene.audio.output != OutputFormat::kAmbisonics;
  try {
    return std::make_unique<audio::AudioOutput>(ao, &renderSession, session);
  } catch (const std::exception& e) {
    why = e.what();
    return nullptr;
  }
}

std::unique_ptr<audio::AudioOutput> openOutput(const SceneDesc& scene, const Flags& fl,
                                               std::unique_ptr<LiveSession>* session) {
  std::string why;
  auto output = tryOpenOutput(scene, fl, session, why);
  if (output) return output;
  // One line: the device layer's reason, plus the way out if it does not already say it.
  if (why.find("--offline") != std::string::npos)
    std::fprintf(stderr, "dpc-demo: %s\n", why.c_str());
  else
    std::fprintf(stderr,
                 "dpc-demo: %s; render with --offline OUT.wav, or start a JACK server "
                 "(jackd -d dummy -r %d -p 128); --list-devices shows what PortAudio sees\n",
                 why.c_str(), scene.audio.sampleRate);
  return nullptr;
}

}  // namespace dpc::demo
