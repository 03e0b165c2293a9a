// WAV file reading and writing (libsndfile).
//
// AudioData is a block of planar float samples at one sample rate: channels[c][frame]. It is
// plain data; whoever holds it owns it. readWav/writeWav run on the control thread (or an
// offline render thread): they allocate, make system calls and throw. Never call them on the
// audio thread.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "common/output_file.h"

namespace dpc::audio {

/// Planar audio: channels[c][i] is sample i of channel c, nominally in [-1, 1].
struct AudioData {
  int sampleRate = 0;                        ///< Hz
  std::vector<std::vector<float>> channels;  ///< planar; all channels have the same length
  /// Number of frames (samples per channel); 0 when there are no channels.
  size_t frames() const { return channels.empty() ? 0 : channels.front().size(); }
};

/// Sample encoding of a written WAV file.
enum class SampleFormat {
  kFloat32,  ///< IEEE float, 32 bit: lossless for float data, values beyond [-1, 1] kept
  kPcm24,    ///< signed integer, 24 bit: values clipped to [-1, 1), quantised to 2^-23
  kPcm16,    ///< signed integer, 16 bit: values clipped to [-1, 1), quantised to 2^-15
};

/// Reads a sound file (any format libsndfile reads: WAV, AIFF, FLAC, ...) into planar float.
/// Integer formats are scaled to [-1, 1) (libsndfile's normalisation).
/// Throws InputError(path, "", "cannot read: <reason>") if the file is missing, unreadable,
/// not audio, or holds no frames. Control thread; allocates.
AudioData readWav(const std::string& path);

/// What a sound file holds, from its header: rate (Hz), channels, frames per channel.
struct SoundFileInfo {
  int sampleRate = 0;
  int channels = 0;
  size_t frames = 0;
};

/// The header of a sound file readWav() would read, without its samples (for memory
/// estimates). Throws as readWav. Control thread; allocates nothing beyond libsndfile's handle.
SoundFileInfo readSoundFileInfo(const std::string& path);

/// Writes `audio` as a WAV file (RIFF/WAVE, whatever the extension of `path`).
/// Atomic replace: the data goes to a temporary file in the same folder, which is renamed to
/// `path` only once complete; on any failure the temporary is removed and `path` is untouched.
/// Throws InputError(path, "", reason) if the folder is missing or not writable, or if the data
/// is invalid: no channels, no frames, channels of unequal length, sampleRate <= 0, or a NaN or
/// infinite sample. Control thread; allocates.
void writeWav(const std::string& path, const AudioData& audio,
              SampleFormat format = SampleFormat::kFloat32);

/// As writeWav, but the complete temporary is returned instead of renamed to `path`, for a
/// run that renames all its outputs together (OutputSet, common/output_file.h).
TempOutputFile stageWav(const std::string& path, const AudioData& audio,
                        SampleFormat format = SampleFormat::kFloat32);

/// Writes a WAV file block by block, so that memory does not grow with its length.
/// The samples go to a temporary file (PATH.tmp-XXXXXX) in the destination folder, which
/// commit() renames to `path`; if commit() is never reached (an exception, a failed render) the
/// destructor removes the temporary and `path` is untouched. No PEAK chunk is written, so the
/// same samples always give the same bytes.
/// Control thread or an offline render thread; allocates one chunk buffer; every member throws
/// InputError(path, "", "cannot write: <reason>") on failure (the temporary is then removed).
class WavStreamWriter {
 public:
  /// Creates the temporary file. Throws if the folder is missing or not writable, sampleRate
  /// <= 0, channels < 1, or libsndfile refuses the format.
  WavStreamWriter(const std::string& path, int sampleRate, int channels,
                  SampleFormat format = SampleFormat::kFloat32);
  ~WavStreamWriter();
  WavStreamWriter(const WavStreamWriter&) = delete;
  WavStreamWriter& operator=(const WavStreamWriter&) = delete;

  /// Appends `frames` frames of planar data (planar[c][i], c < channels), each sample
  /// multiplied by `gain` before writing. A NaN or infinite sample (after the gain) is refused,
  /// naming channel and frame.
  void write(const float* const* planar, size_t frames, float gain = 1.f);
  /// Largest |sample| written so far (after the gain).
  float peak() const { return peak_; }
  /// Frames written so far.
  size_t frames() const { return frames_; }
  /// Multiplies every sample written so far by `gain`, in place, reading and rewriting the
  /// temporary file chunk by chunk (a second streaming pass: memory independent of length).
  /// float32 only (an integer file would be quantised twice): throws std::logic_error otherwise.
  void rescale(float gain);
  /// Closes the temporary file and renames it to `path`. Throws if no frame was written or the
  /// file cannot be completed (disk full) or renamed.
  void commit();
  /// Closes the temporary file and hands it over, complete but not renamed (for an OutputSet).
  /// Throws as commit() before the rename; the writer is closed afterwards.
  TempOutputFile finish();

 private:
  [[noreturn]] void fail(const std::string& reason);
  std::string path_;
  std::optional<TempOutputFile> tmp_;  ///< the temporary PATH.tmp-XXXXXX until commit()
  int channels_ = 0;
  SampleFormat format_;
  void* handle_ = nullptr;  ///< SNDFILE*
  std::vector<float> interleaved_;
  size_t frames_ = 0;
  float peak_ = 0.f;
};

}  // namespace dpc::audio
