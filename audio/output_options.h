// What a live output stream is opened with and reports, shared by AudioOutput
// (audio/audio_output.h) and its backends (audio/output_backend.h): the render callback's
// type, the stream's options and the callback thread's scheduling. Plain types.
//
// Threads: any (the callback type's own rule is below). Allocation: the options' strings. Errors:
// none here (AudioOutput's constructor checks the options).
#pragma once

#include <string>
#include <vector>

namespace dpc::audio {

/// The function the audio thread calls for every block: write `frames` samples to
/// each out[c][0..frames), c < channels (planar float32, nominal range [-1, 1]); every
/// sample must be written (the buffers hold garbage on entry). `frames` is the block size
/// the stream was opened with (PortAudio) or the JACK server's period (JACK: blockSize(),
/// which the server may change while playing). Runs on the audio thread: must not allocate, lock,
/// log, throw, wait or make system calls. The calling thread is declared rt::ThreadRole::kAudio
/// (audio/rt_check.h) before each call, so DPC_ASSERT_AUDIO_THREAD() holds inside. noexcept is part
/// of the type so that a throwing function does not convert silently.
using RenderCallback = void (*)(void* user, float* const* out, int frames) noexcept;

/// Most output ports of a JACK stream (an order-7 Ambisonic signal has 64 channels).
inline constexpr int kMaxJackChannels = 64;

/// What an output stream is opened with (AudioOutput's constructor checks it).
struct OutputOptions {
  std::string device;           ///< device spec (audio/device_name.h; "" = default)
  double sampleRate = 48000.0;  ///< Hz; must be supported by the device (JACK: the server's)
  int channels = 2;             ///< output channels, 1 .. device's maxOutputChannels
  /// Frames per callback (> 0); PortAudio: fixed; JACK: ignored, the server's period.
  int blockSize = 128;
  /// Requested output latency in seconds; <= 0: the device's default low output latency.
  double suggestedLatency = 0.0;
  /// JACK: the output ports' names, one per channel (empty: "out_1", "out_2", ...).
  std::vector<std::string> channelNames;
  /// JACK: the client's name (the server appends "-01"... if it is taken).
  std::string clientName = "dpc";
  /// JACK with the default target: connect to the physical playback ports (false: leave
  /// the ports unconnected, e.g. Ambisonic channels that no loudspeaker plays directly).
  bool connectPhysical = true;
};

/// Scheduling of the callback thread as the OS reports it (known once a callback ran while
/// the stream is active). On ALSA the stream asks PortAudio for SCHED_FIFO; on JACK the
/// server decides (jackd -R gives the process thread SCHED_FIFO).
struct CallbackScheduling {
  bool known = false;
  bool realTime = false;  ///< SCHED_FIFO or SCHED_RR
  int priority = 0;       ///< sched_priority (0 for SCHED_OTHER)
  const char* policy = "unknown";
};

}  // namespace dpc::audio
