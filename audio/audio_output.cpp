#include "audio/audio_output.h"

#include <cstdio>
#include <stdexcept>
#include <string>

#include "audio/jack_backend.h"
#include "audio/output_backend.h"
#include "audio/portaudio_backend.h"

namespace dpc::audio {

AudioOutput::AudioOutput(const Options& options, RenderCallback callback, void* user) {
  if (!callback) throw std::invalid_argument("AudioOutput: null render callback");
  if (!(options.sampleRate > 0.0) || options.channels <= 0 || options.blockSize <= 0) {
    throw std::invalid_argument("AudioOutput: sample rate, channels and block size must be > 0");
  }
  const DeviceRoute route = routeDeviceSpec(options.device, &jackServerRunning);
  if (route.backend == DeviceRoute::Backend::kJack)
    impl_ = openJackOutput(options, route.name);
  else
    impl_ = openPortAudioOutput(options, route.name);
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
