// CallbackWatchdog: notices from the control thread that an audio device has stopped calling
// back (its server gone, the device lost), so that a live session can end instead of hanging.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>

#include "audio/audio_output.h"

namespace dpc::audio {

/// Watches a started AudioOutput from the control thread for a device that has failed: its
/// stream no longer active (a device error) or no callback for the stall time (a JACK server
/// that disappeared leaves the stream "active" with no callbacks). The stall time is
/// max(0.5 s, 8 block periods); the first callback gets 1 s more.
class CallbackWatchdog {
 public:
  /// Starts watching now (call right after output.start()). Control thread; no allocation.
  explicit CallbackWatchdog(const AudioOutput& output);
  /// Control thread, called regularly (every 10 ms or so): "" while the device plays, else
  /// one line saying what failed ("no audio callback for 0.52 s: the audio server stopped or
  /// the device was lost"). Allocates only for the failure's text.
  std::string check();

 private:
  const AudioOutput& output_;
  double stallSeconds_;
  uint64_t callbacks_ = 0;
  std::chrono::steady_clock::time_point lastProgress_;
  bool started_ = false;  ///< a callback has run
};

}  // namespace dpc::audio
