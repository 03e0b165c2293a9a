// Tests for audio/wav_io: round trips, multi-channel, and every refusal names the file.
#include "audio/wav_io.h"

#include <unistd.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <utility>

#include "common/input_error.h"

using dpc::InputError;
using dpc::audio::AudioData;
using dpc::audio::readWav;
using dpc::audio::SampleFormat;
using dpc::audio::writeWav;
namespace fs = std::filesystem;

namespace {

// A fresh, empty folder per test case, removed afterwards.
struct TempDir {
  fs::path path;
  TempDir() {
    path = fs::temp_directory_path() /
           ("dpc_wav_io_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter()++));
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() { fs::remove_all(path); }
  static int& counter() {
    static int c = 0;
    return c;
  }
  std::string file(const std::string& name) const { return (path / name).string(); }
};

/// Writes `channels` at 48 kHz as `format` to dir's file `name`; returns its path.
std::string writeIn(const TempDir& dir, const std::string& name,
                    std::vector<std::vector<float>> channels, SampleFormat format) {
  const std::string path = dir.file(name);
  AudioData a;
  a.sampleRate = 48000;
  a.channels = std::move(channels);
  writeWav(path, a, format);
  return path;
}

/// Overwrites the size field of the WAV's data chunk with `size` (little-endian host) and
/// returns the byte offset of the chunk's "data" tag; the samples follow 8 bytes after it.
size_t setDataSize(const std::string& path, uint32_t size) {
  std::string file(fs::file_size(path), '\0');
  std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
  f.read(file.data(), std::streamsize(file.size()));
  const size_t data = file.find("data");
  REQUIRE(data != std::string::npos);
  f.seekp(std::streamoff(data + 4));
  f.write(reinterpret_cast<const char*>(&size), 4);
  return data;
}

// Random samples in [-amplitude, amplitude], fixed seed.
AudioData randomAudio(int channels, size_t frames, int rate, float amplitude, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> dist(-amplitude, amplitude);
  AudioData a;
  a.sampleRate = rate;
  a.channels.assign(size_t(channels), std::vector<float>(frames));
  for (auto& ch : a.channels)
    for (float& x : ch) x = dist(rng);
  return a;
}

float maxAbsDiff(const AudioData& a, const AudioData& b) {
  float m = 0;
  for (size_t c = 0; c < a.channels.size(); ++c)
    for (size_t i = 0; i < a.frames(); ++i)
      m = std::max(m, std::abs(a.channels[c][i] - b.channels[c][i]));
  return m;
}

size_t filesIn(const fs::path& dir) {
  size_t n = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir)) ++n;
  return n;
}

}  // namespace

TEST_CASE("float32 round trip is bit exact, including values beyond full scale") {
  TempDir dir;
  AudioData a = randomAudio(1, 4096, 48000, 2.0f, 1);
  a.channels[0][7] = 1e-30f;  // tiny values survive too
  writeWav(dir.file("a.wav"), a);
  const AudioData b = readWav(dir.file("a.wav"));
  REQUIRE(b.sampleRate == 48000);
  REQUIRE(b.channels.size() == 1);
  REQUIRE(b.frames() == a.frames());
  CHECK(b.channels == a.channels);
  CHECK(filesIn(dir.path) == 1);  // no temporary left behind
}

TEST_CASE("PCM round trips are within quantisation") {
  TempDir dir;
  const AudioData a = randomAudio(2, 3000, 44100, 0.9f, 2);
  // One LSB is 2^-(bits-1). Rounding costs half an LSB; libsndfile's float->int scale (2^(bits-1)
  // - 1 in some versions) versus its int->float scale (2^-(bits-1)) adds < 1 LSB at full scale.
  SECTION("24 bit") {
    writeWav(dir.file("a.wav"), a, SampleFormat::kPcm24);
    const AudioData b = readWav(dir.file("a.wav"));
    REQUIRE(b.frames() == a.frames());
    REQUIRE(b.channels.size() == 2);
    CHECK(maxAbsDiff(a, b) <= 1.5f * std::ldexp(1.0f, -23));
    CHECK(maxAbsDiff(a, b) > 0.0f);  // it really was quantised
  }
  SECTION("16 bit") {
    writeWav(dir.file("a.wav"), a, SampleFormat::kPcm16);
    const AudioData b = readWav(dir.file("a.wav"));
    REQUIRE(b.frames() == a.frames());
    CHECK(maxAbsDiff(a, b) <= 1.5f * std::ldexp(1.0f, -15));
    CHECK(maxAbsDiff(a, b) > std::ldexp(1.0f, -23));  // coarser than 24 bit
  }
  SECTION("16 bit clips instead of wrapping") {
    AudioData loud = a;
    loud.channels[0][0] = 1.7f;
    loud.channels[1][0] = -1.7f;
    writeWav(dir.file("a.wav"), loud, SampleFormat::kPcm16);
    const AudioData b = readWav(dir.file("a.wav"));
    CHECK(b.channels[0][0] > 0.999f);
    CHECK(b.channels[1][0] <= -0.999f);
  }
}

TEST_CASE("multi-channel data keeps channel order") {
  TempDir dir;
  AudioData a;
  a.sampleRate = 32000;
  const int channels = 6;
  for (int c = 0; c < channels; ++c) {
    std::vector<float> ch(500);
    for (size_t i = 0; i < ch.size(); ++i) ch[i] = float(c + 1) * 0.1f + float(i) * 1e-4f;
    a.channels.push_back(ch);
  }
  writeWav(dir.file("six.wav"), a);
  const AudioData b = readWav(dir.file("six.wav"));
  REQUIRE(b.channels.size() == size_t(channels));
  REQUIRE(b.sampleRate == 32000);
  CHECK(b.channels == a.channels);
}

TEST_CASE("reading a missing file names the file") {
  TempDir dir;
  const std::string path = dir.file("nope.wav");
  try {
    readWav(path);
    FAIL("no exception");
  } catch (const InputError& e) {
    CHECK(e.file() == path);
    CHECK(std::string(e.what()).rfind(path + ": cannot read", 0) == 0);
  }
}

TEST_CASE("a non-WAV file and an empty file are refused") {
  TempDir dir;
  const std::string text = dir.file("notes.wav");
  std::ofstream(text) << "this is not a sound file, just text pretending to be one\n";
  CHECK_THROWS_AS(readWav(text), InputError);
  CHECK_THROWS_WITH(readWav(text), Catch::StartsWith(text + ": cannot read"));

  const std::string empty = dir.file("empty.wav");
  std::ofstream{empty};
  CHECK_THROWS_WITH(readWav(empty), Catch::StartsWith(empty + ": cannot read"));
}

TEST_CASE("a WAV cut short of its data chunk is refused, a streamed size of ~0 is read") {
  TempDir dir;  // 44-byte header, 2000 bytes of samples
  const std::string path =
      writeIn(dir, "cut.wav", {std::vector<float>(1000, 0.25f)}, SampleFormat::kPcm16);
  REQUIRE(fs::file_size(path) == 2044);
  fs::resize_file(path, 1044);
  CHECK_THROWS_WITH(readWav(path),
                    path +
                        ": cannot read: truncated: its data chunk lacks the last 1000 bytes "
                        "(an interrupted copy or download?)");
  CHECK_THROWS_WITH(dpc::audio::readSoundFileInfo(path), Catch::Contains("truncated"));
  // The data size a streaming writer leaves when the length is unknown: read to the end.
  REQUIRE(setDataSize(path, 0xFFFFFFFFu) == 36);
  CHECK(readWav(path).frames() == 500);
}

TEST_CASE("a WAV whose data chunk ends in a partial frame is refused") {
  // 16- and 24-bit PCM and 32-bit float (its header carries a fact chunk): the last stereo
  // frame cut to its left sample, in the declared size and the file alike. libsndfile would
  // read 999 frames and drop the sample without a word.
  for (const auto& [format, bytes] :
       {std::pair{SampleFormat::kPcm16, 2}, std::pair{SampleFormat::kPcm24, 3},
        std::pair{SampleFormat::kFloat32, 4}}) {
    TempDir dir;
    const std::string path =
        writeIn(dir, "partial.wav",
                {std::vector<float>(1000, 0.25f), std::vector<float>(1000, -0.25f)}, format);
    const uint32_t size = 1000 * 2 * bytes - bytes;
    const size_t data = setDataSize(path, size);
    REQUIRE(fs::file_size(path) == data + 8 + 1000 * 2 * bytes);
    fs::resize_file(path, data + 8 + size);
    INFO(bytes << " bytes per sample");
    CHECK_THROWS_WITH(readWav(path),
                      path + ": cannot read: its data chunk ends in a partial frame (" +
                          std::to_string(bytes) + " of " + std::to_string(2 * bytes) +
                          " bytes; a cut or mis-written file?)");
    CHECK_THROWS_WITH(dpc::audio::readSoundFileInfo(path), Catch::Contains("partial frame"));
  }
}

TEST_CASE("a pad byte counted in a WAV's data size is not a partial frame") {
  // 24-bit mono, 999 frames: 2,997 bytes of data and the pad byte RIFF puts after odd-sized
  // chunks. A writer that counts the pad in the size (2,998) made a file libsndfile reads whole.
  TempDir dir;
  const std::string path =
      writeIn(dir, "pad.wav", {std::vector<float>(999, 0.25f)}, SampleFormat::kPcm24);
  const size_t data = setDataSize(path, 2998);
  if (fs::file_size(path) == data + 8 + 2997) fs::resize_file(path, data + 8 + 2998);  // the pad
  CHECK(readWav(path).frames() == 999);
}

TEST_CASE("writing into a missing folder throws and leaves no file") {
  TempDir dir;
  const std::string path = dir.file("missing/out.wav");
  const AudioData a = randomAudio(1, 100, 48000, 0.5f, 3);
  CHECK_THROWS_WITH(writeWav(path, a), Catch::StartsWith(path + ": "));
  CHECK(!fs::exists(dir.path / "missing"));
  CHECK(filesIn(dir.path) == 0);
}

TEST_CASE("writing into a read-only folder throws and leaves nothing") {
  TempDir dir;
  const fs::path ro = dir.path / "ro";
  fs::create_directory(ro);
  fs::permissions(ro, fs::perms::owner_read | fs::perms::owner_exec);
  const bool rootCanWriteAnyway = ::access(ro.c_str(), W_OK) == 0;  // e.g. running as root
  if (!rootCanWriteAnyway) {
    const std::string path = (ro / "out.wav").string();
    CHECK_THROWS_WITH(writeWav(path, randomAudio(1, 100, 48000, 0.5f, 4)),
                      Catch::StartsWith(path + ": "));
    CHECK(filesIn(ro) == 0);
  }
  fs::permissions(ro, fs::perms::owner_all);
}

TEST_CASE("invalid data is refused and an existing file is left untouched") {
  TempDir dir;
  const std::string path = dir.file("keep.wav");
  const AudioData good = randomAudio(1, 64, 48000, 0.5f, 5);
  writeWav(path, good);

  AudioData unequal = randomAudio(2, 64, 48000, 0.5f, 6);
  unequal.channels[1].pop_back();
  CHECK_THROWS_WITH(writeWav(path, unequal),
                    Catch::StartsWith(path + ": ") && Catch::Contains("channel 1"));
  AudioData none;
  none.sampleRate = 48000;
  CHECK_THROWS_AS(writeWav(path, none), InputError);
  AudioData nan = good;
  nan.channels[0][3] = std::nanf("");
  CHECK_THROWS_WITH(writeWav(path, nan), Catch::Contains("frame 3"));
  AudioData badRate = good;
  badRate.sampleRate = 0;
  CHECK_THROWS_AS(writeWav(path, badRate), InputError);

  CHECK(readWav(path).channels == good.channels);
  CHECK(filesIn(dir.path) == 1);
}

TEST_CASE("streamed writing: blocks, gain, in-place rescale, and nothing left on failure") {
  using dpc::audio::WavStreamWriter;
  TempDir dir;
  const AudioData a = randomAudio(2, 20000, 44100, 0.8f, 7);  // spans several 8192-frame chunks
  const std::string path = dir.file("s.wav");
  {
    WavStreamWriter w(path, 44100, 2);
    // Uneven blocks, as a renderer's last block is cut to the duration.
    for (size_t start = 0; start < a.frames(); start += 777) {
      const size_t n = std::min<size_t>(777, a.frames() - start);
      const float* planar[2] = {a.channels[0].data() + start, a.channels[1].data() + start};
      w.write(planar, n, 2.f);  // times 2 is exact in float
    }
    CHECK(w.frames() == a.frames());
    CHECK(!fs::exists(path));  // only the temporary exists until commit
    w.rescale(0.25f);          // exact too: the file now holds a * 0.5
    w.commit();
  }
  const AudioData b = readWav(path);
  REQUIRE(b.frames() == a.frames());
  for (size_t c = 0; c < 2; ++c)
    for (size_t i = 0; i < a.frames(); ++i) REQUIRE(b.channels[c][i] == a.channels[c][i] * 0.5f);
  CHECK(filesIn(dir.path) == 1);

  // Abandoned (an exception ends the render): the temporary is removed, the old file kept.
  {
    WavStreamWriter w(path, 44100, 1);
    const float* planar[1] = {a.channels[0].data()};
    w.write(planar, 100);
  }
  CHECK(readWav(path).channels == b.channels);
  CHECK(filesIn(dir.path) == 1);

  // A non-finite sample fails at once, naming the frame counted over all blocks.
  {
    std::vector<float> x(50, 0.1f);
    x[10] = INFINITY;
    WavStreamWriter w(dir.file("n.wav"), 48000, 1);
    const float* planar[1] = {x.data()};
    w.write(planar, 5);
    CHECK_THROWS_WITH(w.write(planar, 50), Catch::Contains("frame 15"));
  }
  CHECK(filesIn(dir.path) == 1);
}
