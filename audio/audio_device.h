// Live audio output: one output stream of non-interleaved (planar) float32 samples, so the
// render callback has the shape of dpc::AudioStage::process(float* const* out): one float
// array per channel. Two host APIs:
// - JACK's own client library (libjack, https://jackaudio.org/api/): a client whose output
//   ports carry the channels' names (ACN0..., the loudspeakers' labels, left/right), called
//   at the server's period, and told when the server shuts down. Chosen whenever a JACK
//   server is running and the spec asks for JACK or the default.
// - PortAudio (http://www.portaudio.com, v19) for ALSA and OSS, with a fixed block size.
// On a machine without a sound card, run a JACK server with the dummy backend
// (`jackd -d dummy -r 48000 -p 128`, see scripts/jack-headless.sh).
//
// Device selection (`--device SPEC` in the apps):
//   ""  or "default"   JACK (physical playback ports) if a JACK server is running, otherwise
//                      PortAudio's default output device, otherwise the first output device.
//   "jack:" / "jack:system"  JACK, connected to the physical playback ports.
//   "jack:CLIENT"      JACK, connected in order to the input ports of client CLIENT (e.g. an
//                      Ambisonic decoder's); an error if no such client has input ports.
//   "NAME"             the first PortAudio output device whose name contains NAME
//                      (case-insensitive); an exact (case-insensitive) match wins.
//   "HOSTAPI:NAME"     as "NAME" but only among devices of the host API whose name contains
//                      HOSTAPI (case-insensitive): "alsa:hw:0,0", "ALSA:pulse".
//                      "HOSTAPI:" alone is that host API's default output.
//   "portaudio:SPEC"   SPEC through PortAudio even for JACK ("portaudio:jack:system").
//   If HOSTAPI matches no host API, or NAME matches nothing there, the whole SPEC is tried as
//   a NAME (device names may contain ':', e.g. "HDA Intel PCH: ALC892 Analog (hw:0,0)").
// listOutputDevices() (dpc-demo --list-devices) shows PortAudio's names.
//
// Diagnostics: while PortAudio probes (initialisation, termination) ALSA's and JACK's own
// stderr messages ("cannot find card '0'", "jack server is not running") are silenced, since
// on a headless machine they bury the one message that matters; set DPC_AUDIO_VERBOSE=1 to
// see them.
//
// Threads (docs/design.md "Thread roles"): everything here is called on the control thread except
// the RenderCallback, which PortAudio calls on its audio thread (for JACK: the JACK process
// thread) and which must therefore not allocate, lock, log, throw, wait or make system calls.
// The wrapper's own work on the audio thread is two steady_clock reads and a few relaxed
// atomic increments (CallbackStats::record): no allocation, no locks, no system calls.
// std::chrono::steady_clock is clock_gettime(CLOCK_MONOTONIC), served by the vDSO on Linux
// (x86-64, arm64), i.e. a memory read, not a system call.
#pragma once

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace dpc::audio {

/// One PortAudio output device, as listed by listOutputDevices().
struct DeviceInfo {
  std::string name;                      ///< PortAudio device name, e.g. "system" (JACK)
  std::string hostApi;                   ///< host API name, e.g. "JACK Audio Connection Kit"
  int maxOutputChannels = 0;             ///< > 0 for every listed device
  double defaultSampleRate = 0.0;        ///< Hz
  double defaultLowOutputLatency = 0.0;  ///< seconds (PortAudio's estimate for interactive use)
  bool isDefault = false;  ///< the device an empty --device spec opens (see the file comment)
  /// "HOSTAPI:NAME" with the host API's short name ("JACK", "ALSA", "OSS"): a spec that
  /// selects exactly this device's host API.
  std::string spec() const;
};

/// All devices with at least one output channel, in PortAudio's order (grouped by host API).
/// Control thread. Allocates; initialises PortAudio for the duration of the call (host APIs
/// probe their devices: takes up to ~100 ms, and ALSA/JACK may print diagnostics on stderr).
/// Returns an empty vector if there are none. Throws std::runtime_error if PortAudio cannot
/// be initialised.
std::vector<DeviceInfo> listOutputDevices();

/// Callback statistics, written by the audio thread with relaxed atomics and read by the
/// control thread (for a status line such as "audio-callback load (% of the block period)").
/// Counters only grow; a control thread that wants windowed figures subtracts two snapshots
/// (Snapshot::since). Durations are wall-clock nanoseconds of the user's RenderCallback,
/// measured with std::chrono::steady_clock (vDSO, not a system call).
class CallbackStats {
 public:
  /// Histogram of callback durations: log-linear bins, 16 per octave (bin width <= 6.25 % of
  /// the value), exact below 32 ns, covering 0 .. 2^34 ns (17 s); longer durations land in
  /// the last bin.
  static constexpr int kBins = 512;

  /// Bin of a duration in ns, and the largest duration (ns) that falls in a bin. Any thread.
  static int binOf(uint64_t ns) noexcept;
  static uint64_t binUpperNs(int bin) noexcept;

  /// Records one callback of durationNs nanoseconds; xrun: PortAudio reported an output
  /// underflow/overflow (or input under/overflow) for it. Audio thread. Wait-free: relaxed
  /// atomics only, no allocation, no system calls.
  void record(uint64_t durationNs, bool xrun) noexcept;

  /// A copy of the counters at one moment (not an atomic snapshot of all of them together:
  /// the audio thread may record one callback while it is being copied, which at most
  /// miscounts that one callback).
  struct Snapshot {
    uint64_t callbacks = 0;
    uint64_t xruns = 0;                       ///< callbacks flagged with an underflow or overflow
    uint64_t lastNs = 0;                      ///< duration of the most recent callback
    uint64_t maxNs = 0;                       ///< longest callback since the stream was opened
    std::array<uint64_t, kBins> histogram{};  ///< callbacks per duration bin

    /// Duration (ns) below which a fraction q in [0, 1] of the histogram's callbacks fall,
    /// given as the upper edge of the bin that holds the q-quantile, capped at maxNs (so it
    /// errs high by at most one bin width, 6.25 %). 0 if there are no callbacks. Any thread;
    /// no allocation.
    uint64_t quantileNs(double q) const noexcept;
    /// The counters accumulated after `earlier` (a snapshot of the same stats taken
    /// before): callbacks, xruns and histogram are differences, lastNs is this one's and
    /// maxNs is the upper edge of the highest non-empty bin of the difference. No allocation.
    Snapshot since(const Snapshot& earlier) const noexcept;
    /// The counters of two runs together (e.g. two streams of one session, one after the
    /// other): callbacks, xruns and histogram are sums, maxNs the larger, lastNs `later`'s.
    /// No allocation.
    Snapshot plus(const Snapshot& later) const noexcept;
  };
  /// Control thread (any thread). No allocation, wait-free; copies ~4 KB.
  Snapshot snapshot() const noexcept;

 private:
  std::atomic<uint64_t> callbacks_{0};
  std::atomic<uint64_t> xruns_{0};
  std::atomic<uint64_t> lastNs_{0};
  std::atomic<uint64_t> maxNs_{0};
  std::array<std::atomic<uint64_t>, kBins> histogram_{};
};

/// The function the audio thread calls for every block: write `frames` samples to
/// each out[c][0..frames), c < channels (planar float32, nominal range [-1, 1]); every
/// sample must be written (the buffers hold garbage on entry). `frames` is the block size
/// the stream was opened with (PortAudio) or the JACK server's period (JACK: blockSize(),
/// which the server may change while playing). Runs on the audio thread: must not allocate, lock,
/// log, throw, wait or make system calls. The calling thread is declared rt::ThreadRole::kAudio
/// (audio/rt_check.h) before each call, so DPC_ASSERT_AUDIO_THREAD() holds inside. noexcept is part
/// of the type so that a throwing function does not convert silently.
using RenderCallback = void (*)(void* user, float* const* out, int frames) noexcept;

/// One open PortAudio output stream. Opened (not started) by the constructor, closed by the
/// destructor; start()/stop() may alternate. Movable (the stream state lives on the heap, so
/// moving does not disturb a running callback), not copyable. Holds a reference on
/// PortAudio's initialisation: PortAudio stays initialised while any AudioOutput (or a
/// listOutputDevices() call) is alive, and each object releases only its own reference.
class AudioOutput {
 public:
  /// Most output ports of a JACK stream (an order-7 Ambisonic signal has 64 channels).
  static constexpr int kMaxJackChannels = 64;
  struct Options {
    std::string device;           ///< device spec, see the file comment ("" = default)
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
  /// device) if PortAudio cannot start the stream. No effect if already active.
  void start();
  /// Stops after the buffers already rendered have played (Pa_StopStream: waits up to the
  /// output latency); the callback is not running when this returns. Control thread. Throws
  /// std::runtime_error naming the device on failure. No effect if not active.
  void stop();
  /// Whether the callback is being called (started and not stopped or failed). Control
  /// thread; no allocation, no errors.
  bool isActive() const;
  /// stop() that cannot hang: runs Pa_StopStream on a helper thread and waits at most
  /// `seconds` (a device whose server is gone never answers: Pa_StopStream would wait for
  /// ever). True if it returned in time (the stream is stopped as after stop(); a failure to
  /// stop counts as stopped). False otherwise: the helper is left waiting inside PortAudio,
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

  /// The device actually opened: PortAudio name and host API name.
  const DeviceInfo& device() const;
  /// Sample rate the stream runs at (Pa_GetStreamInfo), Hz.
  double sampleRate() const;
  /// Output latency reported by PortAudio for the open stream (Pa_GetStreamInfo), seconds.
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
  /// Scheduling of the callback thread as the OS reports it (known once a callback ran while
  /// the stream is active). On ALSA the stream asks PortAudio for SCHED_FIFO; on JACK the
  /// server decides (jackd -R gives the process thread SCHED_FIFO).
  struct Scheduling {
    bool known = false;
    bool realTime = false;  ///< SCHED_FIFO or SCHED_RR
    int priority = 0;       ///< sched_priority (0 for SCHED_OTHER)
    const char* policy = "unknown";
  };
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
