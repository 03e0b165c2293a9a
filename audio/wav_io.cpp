#include "audio/wav_io.h"

#include <sndfile.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>

#include "engine/input_error.h"
#include "engine/input_file.h"

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

std::string folderOf(const std::string& path) {
  std::filesystem::path parent = std::filesystem::path(path).parent_path();
  return parent.empty() ? std::string(".") : parent.string();
}

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

AudioData readWav(const std::string& path) {
  checkInputFile(path, kMaxSignalBytes, path, "", "cannot read: audio file");
  SF_INFO info{};
  SndFile file;
  file.handle = sf_open(path.c_str(), SFM_READ, &info);
  if (!file.handle) throw InputError(path, "", std::string("cannot read: ") + sf_strerror(nullptr));
  if (info.frames <= 0 || info.channels <= 0)
    throw InputError(path, "", "cannot read: the file holds no audio frames");
  if (info.samplerate <= 0) throw InputError(path, "", "cannot read: invalid sample rate");

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
  validate(path, audio);
  const std::string folder = folderOf(path);
  std::error_code ec;
  if (!std::filesystem::is_directory(folder, ec))
    throw InputError(path, "", "cannot write: folder '" + folder + "' does not exist");

  // The temporary lives next to the target so that the final rename stays on one filesystem.
  std::string tmp = path + ".tmp-XXXXXX";
  const int fd = mkstemp(tmp.data());
  if (fd < 0)
    throw InputError(path, "", "cannot write in folder '" + folder + "': " + std::strerror(errno));
  // mkstemp creates mode 0600; give the file the usual mode a new file would have (0666 & ~umask).
  const mode_t mask = umask(0);
  umask(mask);
  fchmod(fd, 0666 & ~mask);

  auto fail = [&](const std::string& reason) {
    std::remove(tmp.c_str());
    throw InputError(path, "", "cannot write: " + reason);
  };

  SF_INFO info{};
  info.samplerate = audio.sampleRate;
  info.channels = int(audio.channels.size());
  info.format = sndfileFormat(format);
  if (!sf_format_check(&info)) {
    ::close(fd);
    fail("libsndfile refuses this format/channel count");
  }
  SndFile file;
  file.handle = sf_open_fd(fd, SFM_WRITE, &info, SF_TRUE /* close fd with the file */);
  if (!file.handle) {
    ::close(fd);
    fail(sf_strerror(nullptr));
  }
  // Integer formats: clip out-of-range values instead of letting them wrap around.
  sf_command(file.handle, SFC_SET_CLIPPING, nullptr, SF_TRUE);
  // No PEAK chunk: it carries the time of writing, and same-seed renders must be byte-identical.
  sf_command(file.handle, SFC_SET_ADD_PEAK_CHUNK, nullptr, SF_FALSE);

  const size_t channels = audio.channels.size();
  const size_t frames = audio.frames();
  constexpr size_t kChunkFrames = 8192;
  std::vector<float> interleaved(kChunkFrames * channels);
  for (size_t start = 0; start < frames; start += kChunkFrames) {
    const size_t count = std::min(kChunkFrames, frames - start);
    for (size_t i = 0; i < count; ++i)
      for (size_t c = 0; c < channels; ++c)
        interleaved[i * channels + c] = audio.channels[c][start + i];
    if (sf_writef_float(file.handle, interleaved.data(), sf_count_t(count)) != sf_count_t(count)) {
      std::string reason = sf_strerror(file.handle);
      file.close();
      fail(reason);
    }
  }
  if (file.close() != 0) fail("closing the file failed (disk full?)");
  std::filesystem::rename(tmp, path, ec);
  if (ec) fail("renaming the temporary file failed: " + ec.message());
}

}  // namespace dpc::audio
