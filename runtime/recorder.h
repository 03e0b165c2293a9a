// Recorder: keeps what a live session played. The audio thread pushes each engine block
// (planar, `channels` channels) into a fixed ring of interleaved samples (kRingSeconds long);
// a recorder thread of lower importance drains it into per-channel buffers reserved for
// keepSeconds, or, given a path, streams it to a WAV file (a temporary renamed into place by
// commit(), as offline output is), so that memory does not grow with the session and a
// session that ends on a failure keeps what it played. The audio thread never waits for it:
// samples that find the ring full are dropped and counted (droppedSamples()).
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "audio/wav_io.h"
#include "common/fixed_ring.h"

namespace dpc {

class Recorder {
 public:
  /// Ring between the audio thread and the recorder thread, seconds.
  static constexpr double kRingSeconds = 2.0;

  /// sampleRate Hz; channels >= 1; keepSeconds > 0: capacity reserved for the recording
  /// (it grows beyond that if the session runs longer); maxBlockFrames: the largest push().
  /// A non-empty `path`: the recording streams to that float32 WAV file instead (keepSeconds
  /// unused); its temporary is created here. Control thread; allocates; throws InputError
  /// naming `path` if the temporary cannot be created.
  Recorder(int sampleRate, int channels, double keepSeconds, int maxBlockFrames,
           const std::string& path = "");
  ~Recorder();

  /// Control thread: starts the recorder thread (ThreadRole::kWorker). Idempotent.
  void start();
  /// Control thread: drains the ring and joins the recorder thread. Idempotent.
  void stop();

  /// Audio thread: appends planar[c][0..frames) (frames <= maxBlockFrames), c < channels.
  /// Wait-free; no allocation.
  void push(const float* const* planar, int frames) noexcept;
  /// Samples (over all channels) the ring could not take, since construction. Any thread.
  uint64_t droppedSamples() const { return ring_.overflows(); }

  /// Control thread, after stop(): the recording (channels() channels, all of the length of
  /// the shortest), moved out; empty while running or when streaming to a file.
  audio::AudioData take();
  /// Control thread, after stop(), when streaming: renames the file into place and returns
  /// the frames it holds. Throws InputError naming the path if a write failed while the
  /// session ran (a full disk: nothing is renamed, the temporary is removed) or if nothing
  /// was recorded.
  size_t commit();
  int channels() const { return channels_; }

 private:
  void loop();
  /// Moves everything in the ring into recorded_, then, when streaming, the whole frames of
  /// recorded_ into the file. Recorder thread (or stop() after joining).
  void drain();
  /// Streaming: writes the frames all channels of recorded_ hold and removes them; a failure
  /// is kept for commit() and ends the streaming. Recorder thread.
  void writeRecorded();

  int sampleRate_, channels_;
  FixedRing<float> ring_;       ///< interleaved samples
  std::vector<float> scratch_;  ///< audio thread: one interleaved block
  std::vector<float> popped_;   ///< recorder thread: what one pop returned
  std::vector<std::vector<float>> recorded_;
  std::unique_ptr<audio::WavStreamWriter> writer_;  ///< streaming: the file's writer
  std::exception_ptr writeError_;                   ///< streaming: the first write's failure
  size_t phase_ = 0;  ///< channel of the next sample popped (the ring is interleaved)
  std::thread thread_;
  std::atomic<bool> running_{false};
  std::mutex wakeMutex_;
  std::condition_variable wake_;
};

}  // namespace dpc
