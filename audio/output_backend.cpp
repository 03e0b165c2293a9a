#include "audio/output_backend.h"

#include <dlfcn.h>
#include <sched.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <future>
#include <memory>
#include <thread>
#include <utility>

#include "audio/rt_check.h"
#include "common/log.h"

namespace dpc::audio {

namespace {

/// ALSA and JACK print pages of diagnostics on stderr while the backends probe for devices or a
/// server ("cannot find card '0'", "jack server is not running"), which on a machine without a
/// sound card or JACK server bury the one message that matters (ours). Unless
/// DPC_AUDIO_VERBOSE=1, their error handlers are silenced during the probe (Pa_Initialize,
/// Pa_Terminate, a JACK client opened without starting a server) and set back afterwards
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

CallbackScheduling OutputBackend::scheduling() const {
  CallbackScheduling s;
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

}  // namespace dpc::audio
