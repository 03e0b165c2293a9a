#include "audio/callback_watchdog.h"

#include <algorithm>
#include <cstdio>

namespace dpc::audio {

CallbackWatchdog::CallbackWatchdog(const AudioOutput& output)
    : output_(output),
      stallSeconds_(std::max(0.5, 8e-9 * output.blockPeriodNs())),
      callbacks_(output.stats().snapshot().callbacks),
      lastProgress_(std::chrono::steady_clock::now()) {}

std::string CallbackWatchdog::check() {
  const auto now = std::chrono::steady_clock::now();
  const uint64_t callbacks = output_.stats().snapshot().callbacks;
  if (callbacks != callbacks_) {
    callbacks_ = callbacks;
    lastProgress_ = now;
    started_ = true;
    return {};
  }
  if (!output_.isActive()) return "the stream stopped (device error)";
  const double silent = std::chrono::duration<double>(now - lastProgress_).count();
  if (silent < stallSeconds_ + (started_ ? 0.0 : 1.0)) return {};
  char text[160];
  std::snprintf(text, sizeof text,
                "no audio callback for %.2f s: the audio server stopped or the device was lost",
                silent);
  return text;
}

}  // namespace dpc::audio
