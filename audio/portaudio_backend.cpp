#include "audio/portaudio_backend.h"

#include <pa_linux_alsa.h>
#include <portaudio.h>

#include <cstdio>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

#include "audio/output_backend.h"

namespace dpc::audio {

namespace {

constexpr const char* kNoDeviceHint =
    "no audio output device found; render with --offline OUT.wav, or start a JACK server "
    "(e.g. jackd -d dummy -r 48000 -p 128)";

/// Pa_Initialize/Pa_Terminate are reference-counted by PortAudio itself but not thread-safe;
/// this mutex serialises them. Each PaSession holds exactly one reference and releases only
/// that one, so objects never terminate each other's PortAudio.
std::mutex& paInitMutex() {
  static std::mutex m;
  return m;
}

class PaSession {
 public:
  PaSession() {
    std::lock_guard<std::mutex> lock(paInitMutex());
    quietAudioProbing(true);
    const PaError err = Pa_Initialize();
    quietAudioProbing(false);
    if (err != paNoError) {
      throw std::runtime_error(std::string("audio: PortAudio initialisation failed: ") +
                               Pa_GetErrorText(err));
    }
  }
  ~PaSession() {
    std::lock_guard<std::mutex> lock(paInitMutex());
    quietAudioProbing(true);
    Pa_Terminate();
    quietAudioProbing(false);
  }
  PaSession(const PaSession&) = delete;
  PaSession& operator=(const PaSession&) = delete;
};

std::string hostApiShortName(const PaHostApiInfo* api) {
  if (!api) return "?";
  switch (api->type) {
    case paJACK:
      return "JACK";
    case paALSA:
      return "ALSA";
    case paOSS:
      return "OSS";
    default:
      return api->name ? api->name : "?";
  }
}

/// The output device an empty spec opens: JACK's default output if a JACK server is running
/// (its host API then has devices), else PortAudio's default output, else the first output
/// device; paNoDevice if there is no output device. Needs an initialised PortAudio.
PaDeviceIndex defaultOutputDevice() {
  const PaHostApiIndex jack = Pa_HostApiTypeIdToHostApiIndex(paJACK);
  if (jack >= 0) {
    const PaHostApiInfo* api = Pa_GetHostApiInfo(jack);
    if (api && api->defaultOutputDevice != paNoDevice) return api->defaultOutputDevice;
  }
  const PaDeviceIndex def = Pa_GetDefaultOutputDevice();
  if (def != paNoDevice) return def;
  const PaDeviceIndex n = Pa_GetDeviceCount();
  for (PaDeviceIndex i = 0; i < n; ++i) {
    const PaDeviceInfo* info = Pa_GetDeviceInfo(i);
    if (info && info->maxOutputChannels > 0) return i;
  }
  return paNoDevice;
}

DeviceInfo describe(PaDeviceIndex index, PaDeviceIndex defaultIndex) {
  const PaDeviceInfo* info = Pa_GetDeviceInfo(index);
  const PaHostApiInfo* api = Pa_GetHostApiInfo(info->hostApi);
  DeviceInfo d;
  d.name = info->name ? info->name : "";
  d.hostApi = api && api->name ? api->name : "?";
  d.maxOutputChannels = info->maxOutputChannels;
  d.defaultSampleRate = info->defaultSampleRate;
  d.defaultLowOutputLatency = info->defaultLowOutputLatency;
  d.isDefault = index == defaultIndex;
  return d;
}

std::vector<DeviceInfo> listLocked() {
  std::vector<DeviceInfo> out;
  const PaDeviceIndex def = defaultOutputDevice();
  const PaDeviceIndex n = Pa_GetDeviceCount();
  for (PaDeviceIndex i = 0; i < n; ++i) {
    const PaDeviceInfo* info = Pa_GetDeviceInfo(i);
    if (info && info->maxOutputChannels > 0) out.push_back(describe(i, def));
  }
  return out;
}

/// Output devices matching `name` (case-insensitive substring; "" matches all) among the
/// devices of host API `api` (< 0: all host APIs); an exact name match first.
PaDeviceIndex findByName(const std::string& name, PaHostApiIndex api) {
  PaDeviceIndex substringMatch = paNoDevice;
  const PaDeviceIndex n = Pa_GetDeviceCount();
  for (PaDeviceIndex i = 0; i < n; ++i) {
    const PaDeviceInfo* info = Pa_GetDeviceInfo(i);
    if (!info || info->maxOutputChannels <= 0) continue;
    if (api >= 0 && info->hostApi != api) continue;
    const std::string devName = info->name ? info->name : "";
    if (lowerCase(devName) == lowerCase(name)) return i;
    if (substringMatch == paNoDevice && containsNoCase(devName, name)) substringMatch = i;
  }
  return substringMatch;
}

/// Resolves a device spec (audio/device_name.h) to a device index, or throws
/// std::runtime_error naming the spec.
PaDeviceIndex resolveDevice(const std::string& spec) {
  const std::vector<DeviceInfo> all = listLocked();
  const std::string shown = spec.empty() ? "default" : spec;
  if (all.empty()) {
    throw std::runtime_error("audio device '" + shown + "': " + kNoDeviceHint);
  }
  if (spec.empty() || lowerCase(spec) == "default") {
    const PaDeviceIndex d = defaultOutputDevice();
    if (d != paNoDevice) return d;
    throw std::runtime_error("audio device '" + shown + "': " + kNoDeviceHint);
  }
  const size_t colon = spec.find(':');
  if (colon != std::string::npos && colon > 0) {
    const std::string apiPart = spec.substr(0, colon);
    const std::string namePart = spec.substr(colon + 1);
    const PaHostApiIndex apis = Pa_GetHostApiCount();
    for (PaHostApiIndex a = 0; a < apis; ++a) {
      const PaHostApiInfo* api = Pa_GetHostApiInfo(a);
      if (!api || !(containsNoCase(api->name ? api->name : "", apiPart) ||
                    lowerCase(hostApiShortName(api)) == lowerCase(apiPart))) {
        continue;
      }
      if (namePart.empty() && api->defaultOutputDevice != paNoDevice) {
        return api->defaultOutputDevice;
      }
      const PaDeviceIndex d = findByName(namePart, a);
      if (d != paNoDevice) return d;
    }
  }
  const PaDeviceIndex d = findByName(spec, -1);
  if (d != paNoDevice) return d;

  std::string available;
  for (const DeviceInfo& info : all) {
    available += (available.empty() ? "'" : ", '") + info.spec() + "'";
  }
  throw std::runtime_error("audio device '" + spec + "': no output device matches; available: " +
                           available + " (see --list-devices)");
}

std::string formatHz(double hz) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g Hz", hz);
  return buf;
}

class PortAudioBackend final : public OutputBackend {
 public:
  PortAudioBackend(const OutputOptions& options, const std::string& spec);
  ~PortAudioBackend() override { close(); }
  void start() override;
  void stop() override;
  bool isActive() const override { return stream_ && Pa_IsStreamActive(stream_) == 1; }
  bool stopWithin(double seconds) override {
    if (!stream_ || Pa_IsStreamStopped(stream_) == 1) return true;
    PaStream* stream = stream_;
    return runWithin([stream] { Pa_StopStream(stream); }, seconds);
  }
  /// Closes the stream (aborting it if active) and releases PortAudio, so that a device
  /// opened later sees the host APIs' devices afresh.
  void close() override {
    if (stream_) Pa_CloseStream(stream_);
    stream_ = nullptr;
    session_.reset();
  }

 private:
  // PortAudio's audio thread: the shared render() (no allocation, locks or system calls).
  static int paCallback(const void* /*input*/, void* output, unsigned long frames,
                        const PaStreamCallbackTimeInfo* /*timeInfo*/,
                        PaStreamCallbackFlags statusFlags, void* userData) {
    constexpr PaStreamCallbackFlags kXrun =
        paOutputUnderflow | paOutputOverflow | paInputUnderflow | paInputOverflow;
    static_cast<PortAudioBackend*>(userData)->render(static_cast<float* const*>(output),
                                                     int(frames), (statusFlags & kXrun) != 0);
    return paContinue;
  }

  /// First member: initialised before, released after the stream (close()).
  std::optional<PaSession> session_{std::in_place};
  PaStream* stream_ = nullptr;
};

// The stream's output parameters; throws (naming the device) when the device cannot play them.
PaStreamParameters checkedOutputParameters(const OutputOptions& options, PaDeviceIndex index,
                                           const DeviceInfo& device, const std::string& where) {
  if (options.channels > device.maxOutputChannels) {
    throw std::runtime_error(where + ": " + std::to_string(options.channels) +
                             " output channels requested, the device has " +
                             std::to_string(device.maxOutputChannels));
  }
  PaStreamParameters out{};
  out.device = index;
  out.channelCount = options.channels;
  out.sampleFormat = paFloat32 | paNonInterleaved;
  out.suggestedLatency =
      options.suggestedLatency > 0.0 ? options.suggestedLatency : device.defaultLowOutputLatency;
  out.hostApiSpecificStreamInfo = nullptr;
  const PaError supported = Pa_IsFormatSupported(nullptr, &out, options.sampleRate);
  if (supported != paFormatIsSupported) {
    std::string what = Pa_GetErrorText(supported);
    if (supported == paInvalidSampleRate) {
      what = formatHz(options.sampleRate) + " not supported (the device's default rate is " +
             formatHz(device.defaultSampleRate) + "; a JACK device runs only at the " +
             "server's rate)";
    } else if (supported == paInvalidChannelCount) {
      what = std::to_string(options.channels) + " output channels not supported";
    }
    throw std::runtime_error(where + ": " + what);
  }
  return out;
}

PortAudioBackend::PortAudioBackend(const OutputOptions& options, const std::string& spec) {
  const PaDeviceIndex index = resolveDevice(spec);
  device = describe(index, defaultOutputDevice());
  const PaStreamParameters out = checkedOutputParameters(options, index, device, where());
  PaError err = Pa_OpenStream(&stream_, nullptr, &out, options.sampleRate,
                              static_cast<unsigned long>(options.blockSize), paNoFlag,
                              &PortAudioBackend::paCallback, this);
  if (err != paNoError) {
    stream_ = nullptr;
    throw std::runtime_error(where() + ": cannot open a " + std::to_string(options.channels) +
                             "-channel float32 stream at " + formatHz(options.sampleRate) +
                             " with " + std::to_string(options.blockSize) +
                             "-frame blocks: " + Pa_GetErrorText(err));
  }
  // ALSA: ask PortAudio to run the callback thread with SCHED_FIFO (refused without rtprio
  // limits; callbackScheduling() reports what was granted). JACK: the server's -R decides.
  if (const PaHostApiInfo* api = Pa_GetHostApiInfo(Pa_GetDeviceInfo(index)->hostApi);
      api && api->type == paALSA)
    PaAlsa_EnableRealtimeScheduling(stream_, 1);
  const PaStreamInfo* info = Pa_GetStreamInfo(stream_);
  sampleRate = info ? info->sampleRate : options.sampleRate;
  outputLatency = info ? info->outputLatency : 0.0;
  channels = options.channels;
  blockSize = options.blockSize;
}

void PortAudioBackend::start() {
  if (!stream_) throw std::runtime_error(where() + ": the stream was closed");
  if (isActive()) return;
  if (Pa_IsStreamStopped(stream_) != 1) Pa_AbortStream(stream_);  // finished
  const PaError err = Pa_StartStream(stream_);
  if (err != paNoError)
    throw std::runtime_error(where() + ": cannot start the stream: " + Pa_GetErrorText(err));
}

void PortAudioBackend::stop() {
  if (!stream_ || Pa_IsStreamStopped(stream_) == 1) return;
  const PaError err = Pa_StopStream(stream_);
  if (err != paNoError)
    throw std::runtime_error(where() + ": cannot stop the stream: " + Pa_GetErrorText(err));
}

}  // namespace

std::vector<DeviceInfo> listOutputDevices() {
  PaSession session;
  return listLocked();
}

std::unique_ptr<OutputBackend> openPortAudioOutput(const OutputOptions& options,
                                                   const std::string& spec) {
  return std::make_unique<PortAudioBackend>(options, spec);
}

}  // namespace dpc::audio
