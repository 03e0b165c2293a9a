// StudioAudio: the offline clock's sound, for the page to play through Web Audio where no audio
// device plays the session (docs/studio.md, "Listening in the page"). The control loop renders
// each frame period of the stepped session (LiveSession::render, the audio thread's own call)
// and appends it; the server thread copies out what the page has not had yet (GET /api/audio).
//
// Channels: 1 (mono) or 2 (stereo, binaural, ambisonic_binaural): what a browser plays as it
// is. Wider layouts (AmbiX, loudspeaker arrays) are not offered: playable() says so.
// Holds the newest kHeldSeconds; a reader further behind gets the oldest sample held and the
// number it missed (counted, never dropped silently).
//
// Threads: append() control thread, since() server thread, one mutex held only for copies
// (neither is the audio thread: the offline clock has none). Construction allocates the ring;
// since() allocates its chunk; append() does not allocate.
#pragma once

#include <cstddef>
#include <cstdint>
#include <mutex>
#include <vector>

namespace dpc::studio {

class StudioAudio {
 public:
  /// Seconds of sound held for readers (a page polls every 0.1 s; 8 s let a slow one catch up).
  static constexpr double kHeldSeconds = 8.0;
  /// Most frames one since() returns (1 s at 48 kHz: a page's request stays small).
  static constexpr size_t kMaxChunkFrames = 48000;

  /// Whether a session with `deviceChannels` output channels can be played in the page.
  static bool playable(int deviceChannels) { return deviceChannels == 1 || deviceChannels == 2; }

  /// sampleRate: Hz; channels: 1 or 2 (playable()). Throws std::invalid_argument otherwise.
  StudioAudio(int sampleRate, int channels);

  int sampleRate() const { return sampleRate_; }
  int channels() const { return channels_; }

  /// Control thread: appends `frames` samples of each channel (channels() pointers).
  void append(const float* const* channels, size_t frames);

  /// A run of interleaved samples: frames first .. first + frames - 1 of the session's sound
  /// (frame 0 is scene time 0), after `skipped` frames the reader asked for were no longer held.
  struct Chunk {
    uint64_t first = 0;
    uint64_t skipped = 0;
    std::vector<float> interleaved;  ///< frames x channels(), pressure as the device would get
  };
  /// Server thread: the frames from `from` on (at most kMaxChunkFrames; none yet: empty).
  Chunk since(uint64_t from) const;

 private:
  int sampleRate_, channels_;
  size_t capacity_;  ///< frames held
  mutable std::mutex mutex_;
  std::vector<float> ring_;  ///< capacity_ x channels_, interleaved; frame f at f % capacity_
  uint64_t written_ = 0;     ///< frames appended since the start
};

}  // namespace dpc::studio
