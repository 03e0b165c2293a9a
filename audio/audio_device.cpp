#include "audio/audio_device.h"

#include <dlfcn.h>
#include <pa_linux_alsa.h>
#include <portaudio.h>
#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <future>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <thread>
#include <utility>

#include "audio/output_backend.h"
#include "audio/rt_check.h"
#include "common/log.h"

namespace dpc::audio {

namespace {

constexpr const char* kNoDeviceHint =
    "no audio output device found; render with --offline OUT.wav, or start a JACK server "
    "(e.g. jackd -d dummy -r 48000 -p 128)";

/// Pa_Initialize/Pa_Terminate are reference-counted by PortAudio itself but not thread-safe;
/// this mutex serialises them. Each PaSession holds exactly one reference and releases only
/// that one, so objects never terminate each other's PortAudio.
/// ALSA and JACK print pages of diagnostics on stderr while PortAudio probes for devices
/// ("cannot find card '0'", "jack server is not running"), which on a machine without a sound
/// card or JACK server bury the one message that matters (ours). Unless DPC_AUDIO_VERBOSE=1,
/// their error handlers are silenced during Pa_Initialize and Pa_Terminate and set back afterwards
/// (ALSA: its default; JACK: the library's log, stderr by default, as JACK's default prints).
/// Both libraries are loaded with libportaudio, so their setters are looked up with dlsym
/// instead of linking them.
void alsaSilent(const char*, int, const char*, int, const char*, ...) {}
void jackSilent(const char*) {}
void jackErrorToLog(const char* message) {
  logMessage(LogLevel::kError, message);
}
void jackInfoToLog(const char* message) {
  logMessage(LogLevel::kInfo, message);
}

}  // namespace

void quietAudioProbing(bool quiet) {
  using AlsaHandler = void (*)(const char*, int, const char*, int, const char*, ...);
  using AlsaSetHandler = int (*)(AlsaHandler);
  using JackSetFunction = void (*)(void (*)(const char*));
  static const bool verbose = [] {
    const char* v = std::getenv("DPC_AUDIO_VERBOSE");
    return v && std::string(v) == "1";
  }();
  if (verbose) return;
  static const auto alsaSet =
      reinterpret_cast<AlsaSetHandler>(dlsym(RTLD_DEFAULT, "snd_lib_error_set_handler"));
  static const auto jackSetError =
      reinterpret_cast<JackSetFunction>(dlsym(RTLD_DEFAULT, "jack_set_error_function"));
  static const auto jackSetInfo =
      reinterpret_cast<JackSetFunction>(dlsym(RTLD_DEFAULT, "jack_set_info_function"));
  if (alsaSet) alsaSet(quiet ? &alsaSilent : nullptr);
  if (jackSetError) jackSetError(quiet ? &jackSilent : &jackErrorToLog);
  if (jackSetInfo) jackSetInfo(quiet ? &jackSilent : &jackInfoToLog);
}

namespace {

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

std::string lower(std::string s) {
  for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

bool containsNoCase(const std::string& haystack, const std::string& needle) {
  return lower(haystack).find(lower(needle)) != std::string::npos;
}

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
    if (lower(devName) == lower(name)) return i;
    if (substringMatch == paNoDevice && containsNoCase(devName, name)) substringMatch = i;
  }
  return substringMatch;
}

/// Resolves a device spec (see audio_device.h) to a device index, or throws
/// std::runtime_error naming the spec.
PaDeviceIndex resolveDevice(const std::string& spec) {
  const std::vector<DeviceInfo> all = listLocked();
  const std::string shown = spec.empty() ? "default" : spec;
  if (all.empty()) {
    throw std::runtime_error("audio device '" + shown + "': " + kNoDeviceHint);
  }
  if (spec.empty() || lower(spec) == "default") {
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
                    lower(hostApiShortName(api)) == lower(apiPart))) {
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

}  // namespace

std::string DeviceInfo::spec() const {
  std::string api = hostApi;
  if (containsNoCase(hostApi, "jack")) api = "JACK";
  return api + ":" + name;
}

std::vector<DeviceInfo> listOutputDevices() {
  PaSession session;
  return listLocked();
}

// ---------------------------------------------------------------------------------------
// CallbackStats

int CallbackStats::binOf(uint64_t ns) noexcept {
  // Values below 32 have their own bins; above, an octave [2^e, 2^(e+1)) (e >= 5) is split
  // into 16 bins by the 4 bits below the leading one.
  if (ns < 32) return int(ns);
  const int width = std::bit_width(ns);  // e + 1, >= 6
  const int shift = width - 5;           // >= 1
  const int top = int(ns >> shift);      // in [16, 32)
  const int bin = 32 + (shift - 1) * 16 + (top - 16);
  return std::min(bin, kBins - 1);
}

uint64_t CallbackStats::binUpperNs(int bin) noexcept {
  if (bin < 32) return uint64_t(bin);
  const int shift = (bin - 32) / 16 + 1;
  const uint64_t top = uint64_t(16 + (bin - 32) % 16);
  return ((top + 1) << shift) - 1;
}

void CallbackStats::record(uint64_t durationNs, bool xrun) noexcept {
  // Single writer (the audio thread): plain load/store would do for max; fetch_add keeps the
  // counters right even if two threads ever recorded.
  callbacks_.fetch_add(1, std::memory_order_relaxed);
  if (xrun) xruns_.fetch_add(1, std::memory_order_relaxed);
  lastNs_.store(durationNs, std::memory_order_relaxed);
  if (durationNs > maxNs_.load(std::memory_order_relaxed)) {
    maxNs_.store(durationNs, std::memory_order_relaxed);
  }
  histogram_[size_t(binOf(durationNs))].fetch_add(1, std::memory_order_relaxed);
}

CallbackStats::Snapshot CallbackStats::snapshot() const noexcept {
  Snapshot s;
  s.callbacks = callbacks_.load(std::memory_order_relaxed);
  s.xruns = xruns_.load(std::memory_order_relaxed);
  s.lastNs = lastNs_.load(std::memory_order_relaxed);
  s.maxNs = maxNs_.load(std::memory_order_relaxed);
  for (size_t i = 0; i < size_t(kBins); ++i) {
    s.histogram[i] = histogram_[i].load(std::memory_order_relaxed);
  }
  return s;
}

uint64_t CallbackStats::Snapshot::quantileNs(double q) const noexcept {
  uint64_t total = 0;
  for (uint64_t c : histogram) total += c;
  if (total == 0) return 0;
  q = std::clamp(q, 0.0, 1.0);
  // Smallest bin whose cumulative count reaches ceil(q * total) (at least 1).
  uint64_t rank = uint64_t(q * double(total));
  if (double(rank) < q * double(total)) ++rank;
  rank = std::max<uint64_t>(rank, 1);
  uint64_t cumulative = 0;
  for (int b = 0; b < kBins; ++b) {
    cumulative += histogram[size_t(b)];
    // The bin's upper edge, but never above the largest duration recorded.
    if (cumulative >= rank) return maxNs > 0 ? std::min(binUpperNs(b), maxNs) : binUpperNs(b);
  }
  return maxNs;
}

CallbackStats::Snapshot CallbackStats::Snapshot::since(const Snapshot& earlier) const noexcept {
  Snapshot d;
  d.callbacks = callbacks - std::min(callbacks, earlier.callbacks);
  d.xruns = xruns - std::min(xruns, earlier.xruns);
  d.lastNs = lastNs;
  for (size_t i = 0; i < size_t(kBins); ++i) {
    d.histogram[i] = histogram[i] - std::min(histogram[i], earlier.histogram[i]);
    if (d.histogram[i] > 0) d.maxNs = binUpperNs(int(i));
  }
  return d;
}

CallbackStats::Snapshot CallbackStats::Snapshot::plus(const Snapshot& later) const noexcept {
  Snapshot d;
  d.callbacks = callbacks + later.callbacks;
  d.xruns = xruns + later.xruns;
  d.lastNs = later.lastNs;
  d.maxNs = std::max(maxNs, later.maxNs);
  for (size_t i = 0; i < size_t(kBins); ++i) d.histogram[i] = histogram[i] + later.histogram[i];
  return d;
}

// ---------------------------------------------------------------------------------------
// OutputBackend

void OutputBackend::render(float* const* out, int frames, bool xrun) noexcept {
  rt::setThreadRole(rt::ThreadRole::kAudio);  // a thread_local store, see rt_check.h
  if (!callbackThreadKnown_.load(std::memory_order_relaxed)) {
    callbackThread_.store(pthread_self(), std::memory_order_relaxed);
    callbackThreadKnown_.store(true, std::memory_order_release);
  }
  const auto t0 = std::chrono::steady_clock::now();
  callback(user, out, frames);
  const auto t1 = std::chrono::steady_clock::now();
  const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(t1 - t0).count();
  stats.record(uint64_t(std::max<int64_t>(ns, 0)), xrun);
}

AudioOutput::Scheduling OutputBackend::scheduling() const {
  AudioOutput::Scheduling s;
  if (!isActive() || !callbackThreadKnown_.load(std::memory_order_acquire)) return s;
  int policy = 0;
  sched_param param{};
  if (pthread_getschedparam(callbackThread_.load(std::memory_order_relaxed), &policy, &param) != 0)
    return s;
  s.known = true;
  s.realTime = policy == SCHED_FIFO || policy == SCHED_RR;
  s.priority = param.sched_priority;
  s.policy = policy == SCHED_FIFO ? "SCHED_FIFO" : policy == SCHED_RR ? "SCHED_RR" : "SCHED_OTHER";
  return s;
}

bool runWithin(std::function<void()> work, double seconds) {
  auto done = std::make_shared<std::promise<void>>();
  std::future<void> finished = done->get_future();
  std::thread([work = std::move(work), done] {
    work();
    done->set_value();
  }).detach();
  return finished.wait_for(std::chrono::duration<double>(seconds)) == std::future_status::ready;
}

// ---------------------------------------------------------------------------------------
// PortAudio

namespace {

class PortAudioBackend final : public OutputBackend {
 public:
  PortAudioBackend(const AudioOutput::Options& options, const std::string& spec);
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
PaStreamParameters checkedOutputParameters(const AudioOutput::Options& options, PaDeviceIndex index,
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

PortAudioBackend::PortAudioBackend(const AudioOutput::Options& options, const std::string& spec) {
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

/// "jack:CLIENT" (any case) and the default while a JACK server runs go to JACK's own
/// client library; "portaudio:SPEC" and everything else to PortAudio. Sets `target` to the
/// JACK client to connect to ("" : the physical playback ports).
bool wantsJack(const std::string& spec, std::string& target) {
  const std::string l = lower(spec);
  if (l.rfind("jack:", 0) == 0) {
    target = spec.substr(5);
    if (lower(target) == "system") target.clear();
    return true;
  }
  if ((l.empty() || l == "default") && jackServerRunning()) {
    target.clear();
    return true;
  }
  return false;
}

}  // namespace

AudioOutput::AudioOutput(const Options& options, RenderCallback callback, void* user) {
  if (!callback) throw std::invalid_argument("AudioOutput: null render callback");
  if (!(options.sampleRate > 0.0) || options.channels <= 0 || options.blockSize <= 0) {
    throw std::invalid_argument("AudioOutput: sample rate, channels and block size must be > 0");
  }
  std::string target;
  const std::string& spec = options.device;
  if (lower(spec).rfind("portaudio:", 0) == 0)
    impl_ = std::make_unique<PortAudioBackend>(options, spec.substr(10));
  else if (wantsJack(spec, target))
    impl_ = openJackOutput(options, target);
  else
    impl_ = std::make_unique<PortAudioBackend>(options, spec);
  impl_->callback = callback;
  impl_->user = user;
}

AudioOutput::~AudioOutput() {
  if (abandoned_) (void)impl_.release();  // a helper thread may still be inside the backend
}
AudioOutput::AudioOutput(AudioOutput&&) noexcept = default;
AudioOutput& AudioOutput::operator=(AudioOutput&&) noexcept = default;

void AudioOutput::start() {
  impl_->start();
}
void AudioOutput::stop() {
  impl_->stop();
}
bool AudioOutput::stopWithin(double seconds) {
  if (impl_->stopWithin(seconds)) return true;
  abandoned_ = true;
  return false;
}
void AudioOutput::close() {
  if (!abandoned_) impl_->close();
}
bool AudioOutput::isActive() const {
  return impl_->isActive();
}
const DeviceInfo& AudioOutput::device() const {
  return impl_->device;
}
double AudioOutput::sampleRate() const {
  return impl_->sampleRate;
}
double AudioOutput::outputLatency() const {
  return impl_->outputLatency;
}
int AudioOutput::channels() const {
  return impl_->channels;
}
int AudioOutput::blockSize() const {
  return impl_->blockSize.load(std::memory_order_relaxed);
}
bool AudioOutput::realTimeCallback() const {
  return impl_->realTimeCallback;
}
double AudioOutput::blockPeriodNs() const {
  return 1e9 * double(blockSize()) / impl_->sampleRate;
}
const CallbackStats& AudioOutput::stats() const {
  return impl_->stats;
}
AudioOutput::Scheduling AudioOutput::callbackScheduling() const {
  return impl_->scheduling();
}

std::string AudioOutput::statusLine() const {
  return statusLine(CallbackStats::Snapshot{});
}

std::string AudioOutput::statusLine(const CallbackStats::Snapshot& since) const {
  const CallbackStats::Snapshot s = impl_->stats.snapshot().since(since);
  const bool whole = since.callbacks == 0;
  const uint64_t maxNs = whole ? impl_->stats.snapshot().maxNs : s.maxNs;
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "audio %s %.0f Hz x %d: %llu callbacks, %llu xruns, load median %.1f%% "
                "p99.9 %.1f%% max %.1f%% of %.3f ms",
                impl_->device.spec().c_str(), impl_->sampleRate, blockSize(),
                static_cast<unsigned long long>(s.callbacks),
                static_cast<unsigned long long>(s.xruns), loadPercent(s.quantileNs(0.5)),
                loadPercent(s.quantileNs(0.999)), loadPercent(maxNs), blockPeriodNs() * 1e-6);
  const Scheduling sched = callbackScheduling();
  if (!sched.known) return buf;
  return std::string(buf) + ", callback thread " + sched.policy +
         (sched.realTime ? " " + std::to_string(sched.priority)
                         : " (no real-time priority: JACK needs jackd -R, ALSA rtprio limits)");
}

}  // namespace dpc::audio
