// dpc studio's sound for the page (apps/studio/studio_audio.h): frames come back interleaved
// with their numbers, contiguous across the ring's wrap, at most kMaxChunkFrames at a time; a
// reader further behind than the ring holds gets the oldest frame held and the count it
// missed; a reader ahead, or one that asks for "the newest", gets an empty chunk at the end.
#include <catch2/catch.hpp>
#include <cstdint>
#include <limits>
#include <vector>

#include "apps/studio/studio_audio.h"

using dpc::studio::StudioAudio;

namespace {

/// The value every channel c of frame f carries: unique per frame and channel.
float valueOf(uint64_t f, int c) { return float(f % 100000) + 0.25f * float(c); }

/// Appends `frames` frames numbered from `first` in blocks of `block`.
void appendFrames(StudioAudio& audio, uint64_t first, size_t frames, size_t block) {
  std::vector<std::vector<float>> ch(size_t(audio.channels()), std::vector<float>(block));
  std::vector<const float*> ptr;
  for (auto& c : ch) ptr.push_back(c.data());
  for (size_t done = 0; done < frames; done += block) {
    for (size_t c = 0; c < ch.size(); ++c)
      for (size_t i = 0; i < block; ++i) ch[c][i] = valueOf(first + done + i, int(c));
    audio.append(ptr.data(), block);
  }
}

void checkChunk(const StudioAudio::Chunk& chunk, int channels) {
  for (size_t i = 0; i < chunk.interleaved.size() / size_t(channels); ++i)
    for (int c = 0; c < channels; ++c)
      REQUIRE(chunk.interleaved[i * size_t(channels) + size_t(c)] == valueOf(chunk.first + i, c));
}

}  // namespace

TEST_CASE("StudioAudio: numbered frames, the ring's wrap, readers behind and ahead", "[studio]") {
  const int rate = 1000;  // the ring holds kHeldSeconds x rate = 8000 frames
  StudioAudio audio(rate, 2);
  const auto held = uint64_t(StudioAudio::kHeldSeconds * rate);
  appendFrames(audio, 0, 3000, 100);
  StudioAudio::Chunk c = audio.since(0);
  CHECK(c.first == 0);
  CHECK(c.skipped == 0);
  CHECK(c.interleaved.size() == 2 * 3000);
  checkChunk(c, 2);
  appendFrames(audio, 3000, 9000, 100);  // 12,000 written: the ring has wrapped
  c = audio.since(2500);
  CHECK(c.first == 12000 - held);
  CHECK(c.skipped == 12000 - held - 2500);
  CHECK(c.interleaved.size() == 2 * held);
  checkChunk(c, 2);
  c = audio.since(11950);  // across no wrap, the last 50
  CHECK(c.first == 11950);
  CHECK(c.interleaved.size() == 2 * 50);
  checkChunk(c, 2);
  for (uint64_t from : {uint64_t(12000), uint64_t(20000), std::numeric_limits<uint64_t>::max()}) {
    c = audio.since(from);
    CHECK(c.first == 12000);
    CHECK(c.skipped == 0);
    CHECK(c.interleaved.empty());
  }
}

TEST_CASE("StudioAudio: at most kMaxChunkFrames per chunk, mono, and only 1 or 2 channels",
          "[studio]") {
  StudioAudio audio(48000, 1);
  appendFrames(audio, 0, 2 * StudioAudio::kMaxChunkFrames + 480, 480);
  const StudioAudio::Chunk c = audio.since(10);
  CHECK(c.first == 10);
  CHECK(c.interleaved.size() == StudioAudio::kMaxChunkFrames);
  checkChunk(c, 1);
  CHECK_THROWS_AS(StudioAudio(48000, 4), std::invalid_argument);
  CHECK_THROWS_AS(StudioAudio(0, 2), std::invalid_argument);
  CHECK_FALSE(StudioAudio::playable(4));
  CHECK(StudioAudio::playable(1));
}
