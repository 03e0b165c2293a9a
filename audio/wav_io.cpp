#include "audio/wav_io.h"

#include <sndfile.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <stdexcept>

#include "common/input_error.h"
#include "common/input_file.h"
#include "common/output_file.h"

namespace dpc::audio {

namespace {

// Owns an SNDFILE*; closes it on scope exit.
struct SndFile {
  SNDFILE* handle = nullptr;
  ~SndFile() {
    if (handle) sf_close(handle);
  }
  int close() {
    int rc = handle ? sf_close(handle) : 0;
    handle = nullptr;
    return rc;
  }
};

void validate(const std::string& path, const AudioData& audio) {
  if (audio.channels.empty()) throw InputError(path, "", "cannot write: no channels");
  if (audio.sampleRate <= 0)
    throw InputError(
        path, "",
        "cannot write: sample rate " + std::to_string(audio.sampleRate) + " is not positive");
  const size_t frames = audio.channels.front().size();
  if (frames == 0) throw InputError(path, "", "cannot write: no frames");
  for (size_t c = 0; c < audio.channels.size(); ++c) {
    const auto& ch = audio.channels[c];
    if (ch.size() != frames)
      throw InputError(path, "",
                       "cannot write: channel " + std::to_string(c) + " has " +
                           std::to_string(ch.size()) + " frames but channel 0 has " +
                           std::to_string(frames));
    for (size_t i = 0; i < frames; ++i)
      if (!std::isfinite(ch[i]))
        throw InputError(path, "",
                         "cannot write: channel " + std::to_string(c) + " frame " +
                             std::to_string(i) + " is not finite");
  }
}

int sndfileFormat(SampleFormat format) {
  switch (format) {
    case SampleFormat::kPcm24:
      return SF_FORMAT_WAV | SF_FORMAT_PCM_24;
    case SampleFormat::kPcm16:
      return SF_FORMAT_WAV | SF_FORMAT_PCM_16;
    case SampleFormat::kFloat32:
    default:
      return SF_FORMAT_WAV | SF_FORMAT_FLOAT;
  }
}

}  // namespace

namespace {

/// What a RIFF WAVE file's chunks declare, read before libsndfile, whose messages for these
/// cases name neither the field nor the value.
struct WaveChunks {
  /// Bytes of the samples the data chunk declares beyond the end of the file: 0 when none, and
  /// for a declared size of 0 or 0xFFFFFFFF (what streaming writers leave when the length was
  /// unknown; libsndfile judges those). libsndfile reads what is there, so a cut copy would
  /// otherwise play as a shorter signal without a word.
  uint64_t missingDataBytes = 0;
  bool hasFormat = false;  ///< a fmt chunk of at least 8 bytes was read
  uint16_t channels = 0;   ///< as its fmt chunk declares them
  uint32_t sampleRate = 0;
  /// Bytes of a partial last frame: the declared data size modulo the fmt chunk's block
  /// align, for PCM and float samples (libsndfile drops them without a word).
  uint64_t partialFrameBytes = 0;
  uint16_t frameBytes = 0;  ///< bytes per frame (PCM, float and extensible formats), else 0
};

uint32_t littleEndian(const unsigned char* p, int bytes) {
  uint32_t v = 0;
  for (int i = bytes - 1; i >= 0; --i) v = v << 8 | p[i];
  return v;
}

/// A fmt chunk's body of `size` bytes at the stream's position: channels, sample rate and, for
/// PCM (1), float (3) and extensible (0xFFFE) samples, the bytes of a frame: channels times the
/// sample's whole bytes, as readers size it, and only when the block align agrees (a file whose
/// fields disagree is left to the reader, not judged here).
void readFormat(std::ifstream& in, uint64_t size, WaveChunks& out) {
  unsigned char fmt[16];
  const std::streamsize want = size >= 16 ? 16 : 8;
  if (!in.read(reinterpret_cast<char*>(fmt), want)) return;
  out.hasFormat = true;
  out.channels = uint16_t(littleEndian(fmt + 2, 2));
  out.sampleRate = littleEndian(fmt + 4, 4);
  const uint32_t tag = littleEndian(fmt, 2);
  if (want < 16 || (tag != 1 && tag != 3 && tag != 0xFFFE)) return;
  const uint32_t blockAlign = littleEndian(fmt + 12, 2);
  const uint32_t frame = out.channels * ((littleEndian(fmt + 14, 2) + 7) / 8);
  if (frame == blockAlign) out.frameBytes = uint16_t(frame);
}

/// The chunks of a RIFF WAVE file (all defaults for any other file).
WaveChunks readWaveChunks(const std::string& path) {
  WaveChunks out;
  std::ifstream in(path, std::ios::binary);
  unsigned char head[12];
  if (!in.read(reinterpret_cast<char*>(head), 12) || std::memcmp(head, "RIFF", 4) != 0 ||
      std::memcmp(head + 8, "WAVE", 4) != 0)
    return out;
  in.seekg(0, std::ios::end);
  const uint64_t fileBytes = uint64_t(in.tellg());
  uint64_t offset = 12;
  unsigned char chunk[16];
  while (in.seekg(std::streamoff(offset)) && in.read(reinterpret_cast<char*>(chunk), 8)) {
    const uint64_t size = littleEndian(chunk + 4, 4);
    offset += 8;
    if (std::memcmp(chunk, "fmt ", 4) == 0 && size >= 8) readFormat(in, size, out);
    if (std::memcmp(chunk, "data", 4) == 0) {
      const bool unknown = size == 0 || size == 0xFFFFFFFF;
      out.missingDataBytes = unknown || offset + size <= fileBytes ? 0 : offset + size - fileBytes;
      out.partialFrameBytes = unknown || out.frameBytes == 0 ? 0 : size % out.frameBytes;
      // Some writers count the pad byte after odd-sized data in the size: not a sample.
      if (out.partialFrameBytes == 1 && size % 2 == 0) out.partialFrameBytes = 0;
      return out;
    }
    offset += size + (size & 1);
  }
  return out;
}

/// Opens a sound file for reading and checks its header; throws InputError naming the file.
void openSound(const std::string& path, SndFile& file, SF_INFO& info) {
  checkInputFile(path, kMaxSignalBytes, path, "", "cannot read: audio file");
  const WaveChunks wave = readWaveChunks(path);
  if (wave.missingDataBytes)
    throw InputError(path, "",
                     "cannot read: truncated: its data chunk lacks the last " +
                         std::to_string(wave.missingDataBytes) +
                         " bytes (an interrupted copy or download?)");
  if (wave.partialFrameBytes)
    throw InputError(path, "",
                     "cannot read: its data chunk ends in a partial frame (" +
                         std::to_string(wave.partialFrameBytes) + " of " +
                         std::to_string(wave.frameBytes) + " bytes; a cut or mis-written file?)");
  if (wave.hasFormat && (wave.sampleRate == 0 || wave.channels == 0))
    throw InputError(path, "",
                     "cannot read: its fmt chunk declares " +
                         (wave.sampleRate == 0 ? std::string("a sample rate of 0 Hz")
                                               : std::string("0 channels")));
  file.handle = sf_open(path.c_str(), SFM_READ, &info);
  if (!file.handle) throw InputError(path, "", std::string("cannot read: ") + sf_strerror(nullptr));
  if (info.frames <= 0 || info.channels <= 0)
    throw InputError(path, "", "cannot read: the file holds no audio frames");
  if (info.samplerate <= 0) throw InputError(path, "", "cannot read: invalid sample rate");
}

}  // namespace

SoundFileInfo readSoundFileInfo(const std::string& path) {
  SF_INFO info{};
  SndFile file;
  openSound(path, file, info);
  return {info.samplerate, info.channels, size_t(info.frames)};
}

AudioData readWav(const std::string& path) {
  SF_INFO info{};
  SndFile file;
  openSound(path, file, info);

  const size_t channels = size_t(info.channels);
  const size_t frames = size_t(info.frames);
  std::vector<float> interleaved(frames * channels);
  const sf_count_t got = sf_readf_float(file.handle, interleaved.data(), info.frames);
  if (got <= 0) throw InputError(path, "", std::string("cannot read: ") + sf_strerror(file.handle));

  AudioData audio;
  audio.sampleRate = info.samplerate;
  audio.channels.assign(channels, std::vector<float>(size_t(got)));
  for (size_t i = 0; i < size_t(got); ++i)
    for (size_t c = 0; c < channels; ++c) audio.channels[c][i] = interleaved[i * channels + c];
  return audio;
}

void writeWav(const std::string& path, const AudioData& audio, SampleFormat format) {
  stageWav(path, audio, format).commit();
}

TempOutputFile stageWav(const std::string& path, const AudioData& audio, SampleFormat format) {
  validate(path, audio);
  WavStreamWriter writer(path, audio.sampleRate, int(audio.channels.size()), format);
  std::vector<const float*> planar;
  for (const auto& ch : audio.channels) planar.push_back(ch.data());
  writer.write(planar.data(), audio.frames());
  return writer.finish();
}

namespace {
constexpr size_t kChunkFrames = 8192;
SNDFILE* sf(void* h) {
  return static_cast<SNDFILE*>(h);
}
}  // namespace

WavStreamWriter::WavStreamWriter(const std::string& path, int sampleRate, int channels,
                                 SampleFormat format)
    : path_(path), channels_(channels), format_(format) {
  if (sampleRate <= 0)
    throw InputError(
        path, "", "cannot write: sample rate " + std::to_string(sampleRate) + " is not positive");
  if (channels < 1) throw InputError(path, "", "cannot write: no channels");
  SF_INFO info{};
  info.samplerate = sampleRate;
  info.channels = channels;
  info.format = sndfileFormat(format);
  if (!sf_format_check(&info))
    throw InputError(path, "", "cannot write: libsndfile refuses this format/channel count");

  tmp_.emplace(path);  // throws if the folder is missing or not writable
  handle_ = sf_open_fd(tmp_->fd(), SFM_WRITE, &info, SF_TRUE /* close fd with the file */);
  if (!handle_) fail(sf_strerror(nullptr));
  tmp_->releaseFd();  // libsndfile closes it now
  // Integer formats: clip out-of-range values instead of letting them wrap around.
  sf_command(sf(handle_), SFC_SET_CLIPPING, nullptr, SF_TRUE);
  // No PEAK chunk: it carries the time of writing, and same-seed renders must be byte-identical.
  sf_command(sf(handle_), SFC_SET_ADD_PEAK_CHUNK, nullptr, SF_FALSE);
  interleaved_.resize(kChunkFrames * size_t(channels));
}

WavStreamWriter::~WavStreamWriter() {
  if (handle_) sf_close(sf(handle_));
  // tmp_'s destructor removes the temporary unless committed.
}

void WavStreamWriter::fail(const std::string& reason) {
  if (handle_) sf_close(sf(handle_));
  handle_ = nullptr;
  if (tmp_) tmp_->fail(reason);
  throw InputError(path_, "", "cannot write: " + reason);
}

void WavStreamWriter::write(const float* const* planar, size_t frames, float gain) {
  if (!handle_) fail("the file is already closed");
  const size_t channels = size_t(channels_);
  for (size_t start = 0; start < frames; start += kChunkFrames) {
    const size_t count = std::min(kChunkFrames, frames - start);
    for (size_t i = 0; i < count; ++i)
      for (size_t c = 0; c < channels; ++c) {
        const float x = planar[c][start + i] * gain;
        if (!std::isfinite(x))
          fail("channel " + std::to_string(c) + " frame " + std::to_string(frames_ + start + i) +
               " is not finite");
        peak_ = std::max(peak_, std::abs(x));
        interleaved_[i * channels + c] = x;
      }
    if (sf_writef_float(sf(handle_), interleaved_.data(), sf_count_t(count)) != sf_count_t(count))
      fail(sf_strerror(sf(handle_)));
  }
  frames_ += frames;
}

void WavStreamWriter::rescale(float gain) {
  if (format_ != SampleFormat::kFloat32)
    throw std::logic_error("WavStreamWriter::rescale: float32 files only");
  if (!handle_) fail("the file is already closed");
  if (gain == 1.f) return;
  // Close to complete the header, reopen read-write, and rewrite each chunk in place.
  if (sf_close(sf(handle_)) != 0) {
    handle_ = nullptr;
    fail("closing the file failed (disk full?)");
  }
  SF_INFO info{};
  handle_ = sf_open(tmp_->tempPath().c_str(), SFM_RDWR, &info);
  if (!handle_) fail(std::string("reopening the temporary file failed: ") + sf_strerror(nullptr));
  sf_command(sf(handle_), SFC_SET_ADD_PEAK_CHUNK, nullptr, SF_FALSE);
  float peak = 0.f;
  for (size_t start = 0; start < frames_; start += kChunkFrames) {
    const sf_count_t count = sf_count_t(std::min(kChunkFrames, frames_ - start));
    if (sf_seek(sf(handle_), sf_count_t(start), SEEK_SET | SFM_READ) < 0 ||
        sf_readf_float(sf(handle_), interleaved_.data(), count) != count)
      fail(std::string("rereading the temporary file failed: ") + sf_strerror(sf(handle_)));
    for (size_t i = 0; i < size_t(count) * size_t(channels_); ++i) {
      interleaved_[i] *= gain;
      if (!std::isfinite(interleaved_[i])) fail("a sample is not finite after the gain");
      peak = std::max(peak, std::abs(interleaved_[i]));
    }
    if (sf_seek(sf(handle_), sf_count_t(start), SEEK_SET | SFM_WRITE) < 0 ||
        sf_writef_float(sf(handle_), interleaved_.data(), count) != count)
      fail(std::string("rewriting the temporary file failed: ") + sf_strerror(sf(handle_)));
  }
  peak_ = peak;
}

void WavStreamWriter::commit() {
  finish().commit();
}

TempOutputFile WavStreamWriter::finish() {
  if (!handle_) fail("the file is already closed");
  if (frames_ == 0) fail("no frames");
  const int rc = sf_close(sf(handle_));
  handle_ = nullptr;
  if (rc != 0) fail("closing the file failed (disk full?)");
  TempOutputFile file = std::move(*tmp_);
  tmp_.reset();
  return file;
}

}  // namespace dpc::audio
