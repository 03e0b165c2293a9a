// PortAudio devices as dpc-demo lists and opens them.
#include "apps/demo/audio_devices.h"

#include <cstdio>
#include <string>

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

std::unique_ptr<audio::AudioOutput> openOutput(const SceneDesc& scene, const Flags& fl,
                                               LiveSession& session) {
  audio::AudioOutput::Options ao;
  ao.device = fl.device;
  ao.sampleRate = scene.audio.sampleRate;
  ao.channels = 2;
  ao.blockSize = scene.audio.blockSize;
  try {
    return std::make_unique<audio::AudioOutput>(ao, &LiveSession::renderCallback, &session);
  } catch (const std::exception& e) {
    // One line: the device layer's reason, plus the way out if it does not already say it.
    const std::string why = e.what();
    if (why.find("--offline") != std::string::npos)
      std::fprintf(stderr, "dpc-demo: %s\n", why.c_str());
    else
      std::fprintf(stderr,
                   "dpc-demo: %s; render with --offline OUT.wav, or start a JACK server "
                   "(jackd -d dummy -r %d -p 128); --list-devices shows what PortAudio sees\n",
                   why.c_str(), scene.audio.sampleRate);
    return nullptr;
  }
}

}  // namespace dpc::demo
