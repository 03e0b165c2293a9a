// Recorder (runtime/recorder.h): what the audio thread pushes comes back per channel (or in
// the file it streams to), and samples that find the ring full are counted, never waited for.
#include "runtime/recorder.h"

#include <catch2/catch.hpp>
#include <chrono>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "testing/temp_dir.h"

using namespace dpc;

TEST_CASE("Recorder: pushed blocks come back per channel after stop()", "[recorder]") {
  constexpr int kRate = 8000, kBlock = 32;
  Recorder rec(kRate, 2, 1.0, kBlock);
  rec.start();
  std::vector<float> left(kBlock), right(kBlock);
  const float* planar[2] = {left.data(), right.data()};
  std::thread audio([&] {
    for (int b = 0; b < 100; ++b) {
      for (int i = 0; i < kBlock; ++i) {
        left[size_t(i)] = float(b * kBlock + i);
        right[size_t(i)] = -float(b * kBlock + i);
      }
      rec.push(const_cast<float* const*>(planar), kBlock);
    }
  });
  audio.join();
  CHECK(rec.take().channels.empty());  // still running
  rec.stop();
  const audio::AudioData a = rec.take();
  CHECK(rec.droppedSamples() == 0);
  REQUIRE(a.channels.size() == 2);
  REQUIRE(a.frames() == 100 * kBlock);
  CHECK(a.sampleRate == kRate);
  bool same = true;
  for (size_t n = 0; n < a.frames(); ++n)
    same = same && a.channels[0][n] == float(n) && a.channels[1][n] == -float(n);
  CHECK(same);
}

TEST_CASE("Recorder: a full ring drops and counts samples", "[recorder]") {
  constexpr int kRate = 1000, kBlock = 100;  // ring: kRingSeconds * 1000 frames
  Recorder rec(kRate, 1, 1.0, kBlock);       // not started: nothing drains the ring
  std::vector<float> x(kBlock, 0.5f);
  float* planar[1] = {x.data()};
  const int blocks = int(Recorder::kRingSeconds * kRate) / kBlock + 3;
  for (int b = 0; b < blocks; ++b) rec.push(planar, kBlock);
  CHECK(rec.droppedSamples() == 3 * kBlock);
}

TEST_CASE("Recorder: streamed to a file, the same samples, renamed by commit()", "[recorder]") {
  constexpr int kRate = 8000, kBlock = 32;
  const test::TempDir dir("dpc_recorder");
  const std::string path = (dir.path() / "rec.wav").string();
  Recorder rec(kRate, 2, 1.0, kBlock, path);
  rec.start();
  std::vector<float> left(kBlock), right(kBlock);
  const float* planar[2] = {left.data(), right.data()};
  for (int b = 0; b < 300; ++b) {  // 1.2 s: more than the ring holds, drained as it goes
    for (int i = 0; i < kBlock; ++i) {
      left[size_t(i)] = float(b * kBlock + i) / 16384.f;
      right[size_t(i)] = -left[size_t(i)];
    }
    rec.push(const_cast<float* const*>(planar), kBlock);
    if (b % 50 == 0) std::this_thread::sleep_for(std::chrono::milliseconds(30));
  }
  CHECK_FALSE(std::filesystem::exists(path));  // a temporary until commit()
  rec.stop();
  CHECK(rec.take().channels.empty());  // nothing kept in memory
  CHECK(rec.commit() == 300 * kBlock);
  const audio::AudioData a = audio::readWav(path);
  CHECK(rec.droppedSamples() == 0);
  REQUIRE(a.channels.size() == 2);
  REQUIRE(a.frames() == 300 * kBlock);
  bool same = true;
  for (size_t n = 0; n < a.frames(); ++n)
    same =
        same && a.channels[0][n] == float(n) / 16384.f && a.channels[1][n] == -float(n) / 16384.f;
  CHECK(same);
  size_t files = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir.path())) ++files;
  CHECK(files == 1);  // no temporary left
}
