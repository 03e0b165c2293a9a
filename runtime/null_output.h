// NullOutput: a stand-in audio device for machines without one (benchmarks, tests): a thread
// that calls the render callback every block period on a steady clock, like a sound card
// would. Control thread: construct, start, stop. Its thread is the "audio thread"
// (ThreadRole::kAudio).
#pragma once

#include <atomic>
#include <thread>
#include <vector>

#include "audio/callback_stats.h"
#include "audio/output_options.h"

namespace dpc {

class NullOutput {
 public:
  /// sampleRate Hz, blockSize frames per callback, channels output buffers. Allocates.
  NullOutput(int sampleRate, int blockSize, int channels, audio::RenderCallback cb, void* user);
  ~NullOutput();
  /// Control thread: starts calling back. Idempotent.
  void start();
  /// Control thread: stops and joins the thread. Idempotent.
  void stop();
  /// Callback durations and late callbacks (over their block period).
  const audio::CallbackStats& stats() const { return stats_; }

 private:
  void loop();

  int sampleRate_, blockSize_, channels_;
  audio::RenderCallback callback_;
  void* user_;
  std::vector<std::vector<float>> buffers_;
  std::vector<float*> pointers_;
  std::thread thread_;
  std::atomic<bool> running_{false};
  audio::CallbackStats stats_;
};

}  // namespace dpc
