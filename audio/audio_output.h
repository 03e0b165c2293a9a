// AudioOutput: one live output stream of non-interleaved (planar) float32 samples, so the
// render callback has the shape of dpc::AudioStage::process(float* const* out): one float
// array per channel. It forwards to one of two backends (audio/output_backend.h), chosen by
// the device spec (audio/device_name.h):
// - JACK's own client library (audio/jack_backend.h): a client whose output ports carry the
//   channels' names (ACN0..., the loudspeakers' labels, left/right), called at the server's
//   period, and told when the server shuts down. Chosen whenever a JACK server is running and
//   the spec asks for JACK or the default.
// - PortAudio (audio/portaudio_backend.h) for ALSA and OSS, with a fixed block size.
// On a machine without a sound card, run a JACK server with the dummy backend
// (`jackd -d dummy -r 48000 -p 128`, see scripts/jack-headless.sh).
//
// Diagnostics: while the backends probe (PortAudio's initialisation and termination, a JACK
// client opened to see whether a server runs) ALSA's and JACK's own stderr messages ("cannot
// find card '0'", "jack server is not running") are silenced, since on a headless machine
// they bury the one message that matters; set DPC_AUDIO_VERBOSE=1 to see them.
//
// Threads (docs/design.md "Thread roles"): everything here is called on the control thread
// except the RenderCallback, which the backend calls on its audio thread (PortAudio's callback
// thread, JACK's process thread) and which must therefore not allocate, lock, log, throw, wait
// or make system calls. The wrapper's own work on the audio thread is two steady_clock reads
// and a few relaxed atomic increments (CallbackStats::record): no allocation, no locks, no
// system calls. Allocation and errors: per function below.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "audio/callback_stats.h"
#include "audio/device_name.h"
#include "audio/output_options.h"

namespace dpc::audio {

/// One open output stream (PortAudio or JACK). Opened (not started) by the constructor, closed
/// by the destructor; start()/stop() may alternate. Movable (the stream state lives on the
/// heap, so moving does not disturb a running callback), not copyable. A PortAudio stream holds
/// a reference on PortAudio's initialisation: PortAudio stays initialised while any such
/// AudioOutput (or a listOutputDevices() call) is alive, and each object releases only its own
/// reference.
class AudioOutput {
 public:
  /// Most output ports of a JACK stream (audio/output_options.h).
  static constexpr int kMaxJackChannels = audio::kMaxJackChannels;
  /// What the stream is opened with (audio/output_options.h).
  using Options = OutputOptions;

  /// Opens the stream; callback(user, out, frames) will be called once started. callback
  /// must be non-null; user is passed through untouched and must outlive the stream.
  /// Control thread. Allocates; initialises PortAudio (host APIs probe their devices) or
  /// opens a JACK client. Throws std::invalid_argument on a null callback or non-positive
  /// rate/channels/block size, std::runtime_error with a one-line message naming the device
  /// and what failed: PortAudio initialisation failed; no output device at all ("no audio
  /// output device found; render with --offline OUT.wav, or start a JACK server (e.g. jackd
  /// -d dummy -r 48000 -p 128)"); no device matches the spec (the message lists the
  /// available ones); too many channels (JACK: more than kMaxJackChannels); sample rate not
  /// supported (JACK: not the server's); no JACK client CLIENT with input ports; the stream
  /// cannot be opened.
  AudioOutput(const Options& options, RenderCallback callback, void* user);
  /// Closes the stream (aborting it if active) and releases PortAudio. Control thread.
  ~AudioOutput();
  AudioOutput(AudioOutput&&) noexcept;
  AudioOutput& operator=(AudioOutput&&) noexcept;
  AudioOutput(const AudioOutput&) = delete;
  AudioOutput& operator=(const AudioOutput&) = delete;

  /// Starts calling the callback. Control thread. Throws std::runtime_error (naming the
  /// device) if the backend cannot start the stream. No effect if already active.
  void start();
  /// Stops after the buffers already rendered have played (Pa_StopStream: waits up to the
  /// output latency); the callback is not running when this returns. Control thread. Throws
  /// std::runtime_error naming the device on failure. No effect if not active.
  void stop();
  /// Whether the callback is being called (started and not stopped or failed). Control
  /// thread; no allocation, no errors.
  bool isActive() const;
  /// stop() that cannot hang: runs the backend's stop on a helper thread and waits at most
  /// `seconds` (a device whose server is gone never answers: Pa_StopStream would wait for
  /// ever). True if it returned in time (the stream is stopped as after stop(); a failure to
  /// stop counts as stopped). False otherwise: the helper is left waiting inside the backend,
  /// and the stream and this object's PortAudio session are abandoned, never closed (the
  /// destructor then releases nothing, so that it cannot block either); stats() and the
  /// other readers stay valid. Control thread; starts a thread; no errors.
  bool stopWithin(double seconds);
  /// Closes the stream for good (aborting it if active): a failed device's, before the same
  /// device is opened again (libjack crashes closing a client of a dead server once another
  /// client of the process has connected to a new one). device(), stats() and the other
  /// readers stay valid; start() throws std::runtime_error afterwards. No effect on an
  /// abandoned stream (stopWithin() returned false). Control thread; no errors.
  void close();

  /// The device actually opened: its name and host API name. The readers below: any thread
  /// that owns the object; no allocation, no errors.
  const DeviceInfo& device() const;
  /// Sample rate the stream runs at (Pa_GetStreamInfo; JACK: the server's), Hz.
  double sampleRate() const;
  /// Output latency of the open stream (Pa_GetStreamInfo; JACK: the playback ports'), seconds.
  double outputLatency() const;
  int channels() const;
  int blockSize() const;
  /// Duration of one block, blockSize() / sampleRate(), in ns: 100 % callback load.
  double blockPeriodNs() const;
  /// Whether the host promises the callback thread real-time priority before the stream
  /// starts: a JACK server started with -R (jack_is_realtime). False for PortAudio streams,
  /// whose scheduling callbackScheduling() reports once a callback ran. Control thread.
  bool realTimeCallback() const;

  /// The callback statistics (see CallbackStats); any thread may snapshot them.
  const CallbackStats& stats() const;
  /// Scheduling of the callback thread as the OS reports it (audio/output_options.h).
  using Scheduling = CallbackScheduling;
  /// Control thread, while the stream is active (the thread must exist: the control thread
  /// is the one that stops the stream). One system call (pthread_getschedparam).
  Scheduling callbackScheduling() const;
  /// One line for a status display, e.g. "audio 48000 Hz x 128: 37500 callbacks, 0 xruns,
  /// load median 3.1% p99.9 7.9% max 12.4%" (load: callback duration as a percentage of
  /// the block period). Pass a previous snapshot for figures over the window since then.
  /// Control thread; allocates the string.
  std::string statusLine() const;
  std::string statusLine(const CallbackStats::Snapshot& since) const;

  /// Load in % of the block period for a callback duration in ns. Any thread; no allocation.
  double loadPercent(uint64_t durationNs) const {
    return 100.0 * double(durationNs) / blockPeriodNs();
  }

 private:
  std::unique_ptr<class OutputBackend> impl_;
  bool abandoned_ = false;  ///< stopWithin() timed out: impl_ is never destroyed
};

}  // namespace dpc::audio
