// AudioOutput / listOutputDevices without a sound card, and (with DPC_JACK=1, set by
// scripts/jack-headless.sh) real playback through a JACK server:
//   scripts/jack-headless.sh build-dev/audio_device_test "[jack]" -s
#include "audio/audio_output.h"
#include "audio/portaudio_backend.h"

#include <atomic>
#include <catch2/catch.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <thread>

#include "audio/rt_check.h"

using dpc::audio::AudioOutput;
using dpc::audio::CallbackStats;
using dpc::audio::DeviceInfo;
using dpc::audio::listOutputDevices;

namespace {

bool jackRequested() {
  const char* v = std::getenv("DPC_JACK");
  return v && std::string(v) == "1";
}

void noopRender(void*, float* const* out, int frames) noexcept {
  for (int i = 0; i < frames; ++i) out[0][i] = 0.0f;
}

struct Sine {
  double phase = 0.0;
  double step = 0.0;
  int channels = 2;
  std::atomic<bool> wrongRole{false};  ///< a callback ran on a thread not declared kAudio
};

void sineRender(void* user, float* const* out, int frames) noexcept {
  auto* s = static_cast<Sine*>(user);
  if (!dpc::audio::rt::onAudioThread()) s->wrongRole.store(true, std::memory_order_relaxed);
  for (int i = 0; i < frames; ++i) {
    const float v = float(0.2 * std::sin(s->phase));
    s->phase += s->step;
    if (s->phase > 2.0 * M_PI) s->phase -= 2.0 * M_PI;
    for (int c = 0; c < s->channels; ++c) out[c][i] = v;
  }
}

}  // namespace

TEST_CASE("listOutputDevices returns named output devices (possibly none)", "[audio_device]") {
  std::vector<DeviceInfo> devices;
  REQUIRE_NOTHROW(devices = listOutputDevices());
  int defaults = 0;
  for (const DeviceInfo& d : devices) {
    INFO(d.spec());
    CHECK_FALSE(d.name.empty());
    CHECK_FALSE(d.hostApi.empty());
    CHECK(d.maxOutputChannels > 0);
    CHECK(d.defaultSampleRate > 0.0);
    CHECK(d.defaultLowOutputLatency >= 0.0);
    defaults += d.isDefault ? 1 : 0;
  }
  CHECK(defaults <= 1);
  // PortAudio's initialisation is reference-counted: listing twice works.
  CHECK(listOutputDevices().size() == devices.size());
}

TEST_CASE("Opening a device that does not exist names it in the error", "[audio_device]") {
  AudioOutput::Options options;
  options.device = "no-such-device-5f3a";
  try {
    AudioOutput out(options, &noopRender, nullptr);
    FAIL("opened a device that does not exist");
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    INFO(what);
    CHECK(what.find("no-such-device-5f3a") != std::string::npos);
    CHECK(what.find('\n') == std::string::npos);
  }
  options.device = "nohostapi:no-such-device-5f3a";
  CHECK_THROWS_WITH(AudioOutput(options, &noopRender, nullptr),
                    Catch::Contains("nohostapi:no-such-device-5f3a"));
}

TEST_CASE("AudioOutput rejects bad arguments before touching a device", "[audio_device]") {
  AudioOutput::Options options;
  CHECK_THROWS_AS(AudioOutput(options, nullptr, nullptr), std::invalid_argument);
  options.blockSize = 0;
  CHECK_THROWS_AS(AudioOutput(options, &noopRender, nullptr), std::invalid_argument);
}

TEST_CASE("A device spec routes to the backend its prefix names", "[audio_device]") {
  using dpc::audio::DeviceRoute;
  using dpc::audio::routeDeviceSpec;
  using Backend = DeviceRoute::Backend;
  static bool asked = false;
  bool (*running)() = [] {
    asked = true;
    return true;
  };
  bool (*stopped)() = [] {
    asked = true;
    return false;
  };
  auto check = [](const DeviceRoute& r, Backend backend, const std::string& name) {
    CHECK(r.backend == backend);
    CHECK(r.name == name);
  };
  // Explicit prefixes (any case) never ask for a server; "portaudio:" wins over "jack:".
  asked = false;
  check(routeDeviceSpec("portaudio:jack:system", running), Backend::kPortAudio, "jack:system");
  check(routeDeviceSpec("JACK:System", running), Backend::kJack, "");
  check(routeDeviceSpec("jack:", stopped), Backend::kJack, "");
  check(routeDeviceSpec("jack:IEM Decoder", stopped), Backend::kJack, "IEM Decoder");
  check(routeDeviceSpec("alsa:hw:0,0", running), Backend::kPortAudio, "alsa:hw:0,0");
  CHECK_FALSE(asked);
  // The default goes to JACK only while a server runs.
  check(routeDeviceSpec("", running), Backend::kJack, "");
  check(routeDeviceSpec("Default", running), Backend::kJack, "");
  check(routeDeviceSpec("", stopped), Backend::kPortAudio, "");
  check(routeDeviceSpec("default", stopped), Backend::kPortAudio, "default");
  CHECK(asked);
}

TEST_CASE("CallbackStats histogram bins and quantiles", "[audio_device]") {
  // Bins are contiguous and monotone, each at most 1/16 of its value wide above 32 ns.
  uint64_t previousUpper = 0;
  for (int b = 0; b < CallbackStats::kBins; ++b) {
    const uint64_t upper = CallbackStats::binUpperNs(b);
    if (b > 0) REQUIRE(upper > previousUpper);
    REQUIRE(CallbackStats::binOf(upper) == b);
    if (b > 0) REQUIRE(CallbackStats::binOf(previousUpper + 1) == b);
    if (b >= 32) REQUIRE(double(upper - previousUpper) <= double(previousUpper + 1) / 16.0);
    previousUpper = upper;
  }
  CHECK(CallbackStats::binOf(~uint64_t(0)) == CallbackStats::kBins - 1);

  CallbackStats stats;
  CHECK(stats.snapshot().quantileNs(0.5) == 0);
  for (int i = 1; i <= 1000; ++i) stats.record(uint64_t(i) * 1000, i == 500);
  const CallbackStats::Snapshot s = stats.snapshot();
  CHECK(s.callbacks == 1000);
  CHECK(s.xruns == 1);
  CHECK(s.lastNs == 1000000);
  CHECK(s.maxNs == 1000000);
  const double median = double(s.quantileNs(0.5));
  CHECK(median >= 500000.0);
  CHECK(median <= 500000.0 * 1.0625 + 1);
  const double p999 = double(s.quantileNs(0.999));
  CHECK(p999 >= 999000.0);
  CHECK(p999 <= 999000.0 * 1.0625 + 1);
  // The mean of 1..1000 us is 500.5 us; bins' upper edges err high by at most 1/16.
  const double mean = double(s.meanNs());
  CHECK(mean >= 500500.0);
  CHECK(mean <= 500500.0 * 1.0625 + 1);

  for (int i = 0; i < 10; ++i) stats.record(7000, false);
  const CallbackStats::Snapshot window = stats.snapshot().since(s);
  CHECK(window.callbacks == 10);
  CHECK(window.xruns == 0);
  CHECK(window.quantileNs(1.0) >= 7000);
  CHECK(window.maxNs >= 7000);
  CHECK(window.maxNs < 7500);

  // Two streams' windows together: as one stream that saw both.
  const CallbackStats::Snapshot both = s.plus(window);
  CHECK(both.callbacks == 1010);
  CHECK(both.xruns == 1);
  CHECK(both.maxNs == 1000000);
  CHECK(both.lastNs == window.lastNs);
  CHECK(both.quantileNs(0.5) == stats.snapshot().quantileNs(0.5));
}

// Real playback: needs a running JACK server (scripts/jack-headless.sh sets DPC_JACK=1).
TEST_CASE("JACK: a sine plays for 2 s with the expected number of callbacks", "[jack]") {
  if (!jackRequested()) {
    WARN("skipped: DPC_JACK != 1 (run under scripts/jack-headless.sh to test playback)");
    return;
  }
  const std::vector<DeviceInfo> devices = listOutputDevices();
  const DeviceInfo* jack = nullptr;
  for (const DeviceInfo& d : devices) {
    std::printf("output device: %s (%d ch, %.0f Hz, low latency %.2f ms)%s\n", d.spec().c_str(),
                d.maxOutputChannels, d.defaultSampleRate, d.defaultLowOutputLatency * 1e3,
                d.isDefault ? " [default]" : "");
    if (!jack && d.spec().rfind("JACK:", 0) == 0) jack = &d;
  }
  REQUIRE(jack != nullptr);

  AudioOutput::Options options;
  options.device = "jack:" + jack->name;
  options.sampleRate = jack->defaultSampleRate;
  options.channels = std::min(2, jack->maxOutputChannels);
  options.blockSize = 128;
  Sine sine;
  sine.channels = options.channels;
  sine.step = 2.0 * M_PI * 440.0 / options.sampleRate;
  AudioOutput out(options, &sineRender, &sine);
  CHECK(out.device().spec() == jack->spec());
  CHECK(out.sampleRate() == options.sampleRate);
  CHECK_FALSE(out.isActive());

  const double seconds = 2.0;
  out.start();
  CHECK(out.isActive());
  // The first 0.5 s separately: stream start-up (page faults, JACK port connections) is
  // where a non-real-time server tends to report its xruns.
  std::this_thread::sleep_for(std::chrono::duration<double>(0.5));
  const CallbackStats::Snapshot startup = out.stats().snapshot();
  std::this_thread::sleep_for(std::chrono::duration<double>(seconds - 0.5));
  out.stop();
  CHECK_FALSE(out.isActive());

  const CallbackStats::Snapshot s = out.stats().snapshot();
  const double expected = seconds * out.sampleRate() / options.blockSize;
  std::printf("%s\n", out.statusLine().c_str());
  std::printf(
      "jack: %llu callbacks (expected %.0f), %llu xruns, output latency %.2f ms, "
      "callback median %llu ns p99.9 %llu ns max %llu ns (block %.0f ns)\n",
      static_cast<unsigned long long>(s.callbacks), expected,
      static_cast<unsigned long long>(s.xruns), out.outputLatency() * 1e3,
      static_cast<unsigned long long>(s.quantileNs(0.5)),
      static_cast<unsigned long long>(s.quantileNs(0.999)),
      static_cast<unsigned long long>(s.maxNs), out.blockPeriodNs());
  std::printf("jack: first 0.5 s: %llu callbacks, %llu xruns; after: %s\n",
              static_cast<unsigned long long>(startup.callbacks),
              static_cast<unsigned long long>(startup.xruns), out.statusLine(startup).c_str());
  CHECK(double(s.callbacks) > 0.9 * expected);
  CHECK(s.maxNs > 0);
  CHECK_FALSE(sine.wrongRole.load());
  CHECK_FALSE(dpc::audio::rt::onAudioThread());  // the test's own thread

  // Restart after stop, and a second stream while the first is open: each object holds its
  // own PortAudio reference.
  {
    AudioOutput second(options, &noopRender, nullptr);
    CHECK(second.device().name == jack->name);
  }
  const uint64_t before = out.stats().snapshot().callbacks;
  out.start();
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  out.stop();
  CHECK(out.stats().snapshot().callbacks > before);

  // An unsupported rate names the device and the rate.
  options.sampleRate = options.sampleRate == 44100.0 ? 48000.0 : 44100.0;
  CHECK_THROWS_WITH(AudioOutput(options, &noopRender, nullptr),
                    Catch::Contains(jack->name) && Catch::Contains("Hz"));
}
