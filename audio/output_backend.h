// OutputBackend: one open output stream of one host API, the base AudioOutput
// (audio/audio_output.h) forwards to. Two exist: PortAudio's (audio/portaudio_backend.h: ALSA,
// OSS, and JACK through PortAudio) and JACK's own client library (audio/jack_backend.h), which
// names its ports, runs at the server's period and hears the server shut down. The base owns
// what both share: the user's callback, the stream's figures, the callback statistics and the
// callback thread's scheduling. Internal to the audio layer.
//
// Threads: render() on the backend's audio thread; everything else on the control thread.
// Allocation: none in render(); runWithin starts a thread. Errors: per function below.
#pragma once

#include <pthread.h>

#include <atomic>
#include <functional>
#include <string>

#include "audio/callback_stats.h"
#include "audio/device_name.h"
#include "audio/output_options.h"

namespace dpc::audio {

class OutputBackend {
 public:
  virtual ~OutputBackend() = default;
  /// As AudioOutput::start / stop / isActive (control thread; throw std::runtime_error).
  virtual void start() = 0;
  virtual void stop() = 0;
  virtual bool isActive() const = 0;
  /// As AudioOutput::stopWithin: false if the stop did not return within `seconds`; the
  /// caller must then never destroy this backend (a helper thread is still inside it).
  virtual bool stopWithin(double seconds) = 0;
  /// As AudioOutput::close: the stream (client) is closed for good, the fields stay.
  virtual void close() = 0;

  /// Audio thread, once per host callback: declares the thread's role, remembers the thread,
  /// runs the user's callback on out[0..channels)[0..frames) and records its duration.
  /// No allocation, locks or system calls (two vDSO clock reads, relaxed atomics).
  void render(float* const* out, int frames, bool xrun) noexcept;
  /// The callback thread's scheduling (AudioOutput::callbackScheduling); control thread.
  CallbackScheduling scheduling() const;
  /// "audio device 'JACK:system'": the prefix of every error message. Allocates.
  std::string where() const { return "audio device '" + device.spec() + "'"; }

  RenderCallback callback = nullptr;
  void* user = nullptr;
  DeviceInfo device;
  double sampleRate = 0.0;     ///< Hz
  double outputLatency = 0.0;  ///< seconds
  int channels = 0;
  /// Frames per callback (JACK: the server's period, which the server may change while the
  /// stream runs; the atomic lets the control thread read it).
  std::atomic<int> blockSize{0};
  /// Whether the host promises its callback thread real-time priority before the stream
  /// starts (JACK: a server started with -R). PortAudio: false (known only from a callback).
  bool realTimeCallback = false;
  CallbackStats stats;

 private:
  std::atomic<pthread_t> callbackThread_{};
  std::atomic<bool> callbackThreadKnown_{false};
};

/// Runs `work` on a detached helper thread and waits at most `seconds` for it: true if it
/// returned in time. A stop call into an audio server that is gone never returns; this keeps
/// the control thread from waiting with it. Control thread; starts a thread.
bool runWithin(std::function<void()> work, double seconds);

/// While true, ALSA's and JACK's own diagnostics on stderr are silenced (unless
/// DPC_AUDIO_VERBOSE=1): probing for devices or a server prints pages of them on a headless
/// machine. Control thread.
void quietAudioProbing(bool quiet);

}  // namespace dpc::audio
