// NonUniformConvolver against direct convolution in double precision: random IRs (lengths that
// are no multiple of any partition), several sources into two outputs, random IR swaps. The
// expected output follows the per-level crossfade of nonuniform_convolver.h exactly: level l's
// chunk c (output samples [o_l + c N_l, o_l + (c + 1) N_l)) takes the IR that was newest in the
// callback where its input chunk completed, and crossfades from the previous chunk's IR with
// g[n] = min(1, (n + 1) / B) when they differ; staggered, one source group per chunk.
#include "audio/nonuniform_convolver.h"

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <stdexcept>
#include <vector>

#include "tests/audio/convolution_reference.h"

using namespace dpc::audio;

namespace {

using dpc::test::Signal;

using dpc::test::randomSignal;
using dpc::test::segmentConvolution;

/// Tolerance on the relative error energy, as for the uniform convolver
/// (tests/audio/convolver_test.cpp): float rounding u = 2^-24 enters in the forward and
/// inverse FFTs (log2(2 N) stages) and in every term of the spectral multiply-accumulate;
/// treated as independent errors the relative error energy is about u^2 (c1 log2(2 N_max) +
/// c2 P_total); we allow 64 u^2 (log2(2 N_max) + P_total) (relative RMS error 8 u sqrt(...)),
/// never more than -100 dB. The crossfade adds one rounding per sample (within the margin).
double tolerance(const NonUniformLayout& layout, int numSources) {
  const double u = std::ldexp(1.0, -24);
  int maxN = 0;
  for (int l = 0; l < layout.numLevels(); ++l) maxN = std::max(maxN, layout.level(l).partitionSize);
  const double bound =
      64.0 * u * u * (std::log2(2.0 * maxN) + double(layout.totalPartitions() * numSources));
  return std::min(bound, 1e-10);
}

struct Event {
  size_t block;
  int ir;  ///< index into the IR list, -1: no IR
};

/// How runAndCompare runs the convolver and what it reports besides the error.
struct RunOptions {
  bool skipSilentLevels = false;   ///< off: exact whatever the onsets (the convolver's option)
  size_t compareFrom = 0;          ///< first output sample compared with the reference
  uint64_t skippedTransforms = 0;  ///< out: the convolver's counters after the run
  uint64_t stalePartitions = 0;
  int swapSpread = 1;  ///< the convolver's setSwapSpread
};

/// A level's swap in one of its chunks ("Staggered swaps" in nonuniform_convolver.h): the IR
/// before and after (indices into the IR list, -1 none) and the group crossfading while they
/// differ.
struct ChunkSwap {
  int before = -1, after = -1, group = 0;
};

/// The swap state of each of a level's chunks 0..count-1: a chunk starts a swap to the newest
/// IR (newestAtChunk(q)) when no swap is under way, and a swap crossfades one source group per
/// chunk, groups in order, until all have the new IR; but a level with no IR takes the first
/// at once while no input has sounded yet (silentAtChunk(q)).
template <typename Newest, typename Silent>
std::vector<ChunkSwap> chunkSwaps(long long count, int groups, Newest newestAtChunk,
                                  Silent silentAtChunk) {
  std::vector<ChunkSwap> chunks;
  ChunkSwap st;
  for (long long q = 0; q < count; ++q) {
    if (st.after == st.before) st = ChunkSwap{st.before, newestAtChunk(q), 0};
    if (st.before < 0 && silentAtChunk(q)) st.before = st.after;
    chunks.push_back(st);
    if (st.after != st.before && ++st.group == groups) st = ChunkSwap{st.after, st.after, 0};
  }
  return chunks;
}

/// Output channel c as the convolver must produce it: per level, the segment of each IR
/// convolved with each source's input (double precision, direct), and per chunk of the level
/// (shifted by its phase) each source's output with the IR its group uses, or crossfaded from
/// the old IR to the new while its group swaps.
std::vector<double> crossfadeReference(const NonUniformLayout& layout,
                                       const NonUniformConvolver& conv,
                                       const std::vector<std::vector<Signal>>& irs,
                                       const std::vector<Signal>& x, int numSources, int numOutputs,
                                       const std::vector<Event>& events, int c) {
  // Newest IR at callback k (after the events of block k).
  auto newestAt = [&](long long k) {
    int ir = -1;
    for (const Event& ev : events)
      if (static_cast<long long>(ev.block) <= k) ir = ev.ir;
    return ir;
  };
  const size_t b = size_t(layout.blockSize());
  const size_t total = x[0].size();
  // Whether every input sample before callback k is zero.
  size_t firstSound = total;
  for (const Signal& xs : x)
    for (size_t t = 0; t < xs.size() && t < firstSound; ++t)
      if (xs[t] != 0.0f) firstSound = t;
  auto silentBefore = [&](long long k) { return k <= 0 || size_t(k) * b <= firstSound; };
  std::vector<double> expected(total, 0.0);
  for (int l = 0; l < layout.numLevels(); ++l) {
    const NonUniformLayout::Level& lv = layout.level(l);
    const size_t n = size_t(lv.partitionSize);
    const size_t begin = lv.offset, end = lv.offset + size_t(lv.numPartitions) * n;
    // Per IR and source: the level segment's output, the IR weighted by the level's share.
    std::vector<std::vector<std::vector<double>>> seg(irs.size());
    for (size_t i = 0; i < irs.size(); ++i)
      for (int s = 0; s < numSources; ++s) {
        Signal h = irs[i][size_t(s * numOutputs + c)];
        for (size_t t = begin; t < std::min(end, h.size()); ++t) h[t] *= layout.share(l, t);
        seg[i].push_back(segmentConvolution(x[size_t(s)], h, begin, end));
      }
    // The level's chunks are shifted by its phase: local block k + phi (header). Chunk q takes
    // its IR in the callback where its input completed.
    const long long m = lv.period, phase = conv.levelPhase(l);
    const int groups = conv.swapGroups(l);
    const auto callbackOf = [&](long long q) { return (q + 1) * m - 1 - phase; };
    const auto chunks = chunkSwaps((long long)((total + size_t(phase) * b) / n) + 1, groups,
                                   [&](long long q) { return newestAt(callbackOf(q)); },
                                   [&](long long q) { return silentBefore(callbackOf(q)); });
    const auto value = [&](int ir, int s, size_t t) {
      return ir < 0 ? 0.0 : seg[size_t(ir)][size_t(s)][t];
    };
    for (size_t t = begin; t < total; ++t) {
      const size_t local = t - begin + size_t(phase) * b;
      const ChunkSwap& q = chunks[local / n];
      const double g = std::min(1.0, double(local % n + 1) / double(b));
      for (int s = 0; s < numSources; ++s) {
        const int group = s % groups;
        if (q.after == q.before || group > q.group)
          expected[t] += value(q.before, s, t);
        else if (group < q.group)
          expected[t] += value(q.after, s, t);
        else
          expected[t] += (1.0 - g) * value(q.before, s, t) + g * value(q.after, s, t);
      }
    }
  }
  return expected;
}

/// Runs the convolver over x (numBlocks blocks per source) with setNextIr(event) before the
/// event's block, checks against the per-level crossfade reference; returns the relative
/// error energy. IR sets are lent only while at home, as the pipeline does.
/// *worstSample receives the largest single-sample error divided by the reference's RMS.
double runAndCompare(const NonUniformLayout& layout, const std::vector<std::vector<Signal>>& irs,
                     int numSources, int numOutputs, const std::vector<Event>& events,
                     size_t numBlocks, int phaseSlot, std::mt19937& rng, double* worstSample,
                     RunOptions& options) {
  const size_t b = size_t(layout.blockSize());
  const size_t total = numBlocks * b;
  // One set per event (the owner never lends a set twice before it comes back), holding
  // irs[event.ir][s * numOutputs + c].
  std::vector<std::unique_ptr<NonUniformIrSet>> sets;
  for (const Event& ev : events) {
    sets.push_back(std::make_unique<NonUniformIrSet>(layout, numSources, numOutputs));
    if (ev.ir < 0) continue;
    const auto& ir = irs[size_t(ev.ir)];
    for (int s = 0; s < numSources; ++s) {
      std::vector<const float*> ch;
      for (int c = 0; c < numOutputs; ++c) ch.push_back(ir[size_t(s * numOutputs + c)].data());
      sets.back()->prepare(s, ch.data(), ir[size_t(s * numOutputs)].size());
    }
  }
  std::vector<Signal> x;
  for (int s = 0; s < numSources; ++s) x.push_back(randomSignal(rng, total));

  NonUniformConvolver conv(layout, numSources, numOutputs, phaseSlot);
  conv.setSkipSilentLevels(options.skipSilentLevels);
  conv.setSwapSpread(options.swapSpread);
  std::vector<Signal> out(size_t(numOutputs), Signal(total, 0.0f));
  std::vector<char> atHome(sets.size(), 1);
  std::vector<const float*> in(static_cast<size_t>(numSources), nullptr);
  std::vector<float*> o(static_cast<size_t>(numOutputs), nullptr);
  const auto takeHome = [&] {
    while (const NonUniformIrSet* r = conv.takeRetired()) {
      size_t i = 0;
      while (sets[i].get() != r) ++i;
      REQUIRE_FALSE(atHome[i]);  // returned once
      atHome[i] = 1;
    }
  };
  size_t e = 0;
  for (size_t k = 0; k < numBlocks; ++k) {
    for (; e < events.size() && events[e].block == k; ++e) {
      const bool silent = events[e].ir < 0;
      REQUIRE(conv.setNextIr(silent ? nullptr : sets[e].get()));
      if (!silent) atHome[e] = 0;
    }
    for (int s = 0; s < numSources; ++s) in[size_t(s)] = x[size_t(s)].data() + k * b;
    for (int c = 0; c < numOutputs; ++c) o[size_t(c)] = out[size_t(c)].data() + k * b;
    conv.process(in.data(), o.data(), k % 2 == 1);  // add mode on zeroed output: same result
    takeHome();
  }

  double err = 0.0, energy = 0.0, maxErr = 0.0;
  for (int c = 0; c < numOutputs; ++c) {
    const std::vector<double> expected =
        crossfadeReference(layout, conv, irs, x, numSources, numOutputs, events, c);
    for (size_t t = options.compareFrom; t < total; ++t) {
      const double d = double(out[size_t(c)][t]) - expected[t];
      maxErr = std::max(maxErr, std::abs(d));
      err += d * d;
      energy += expected[t] * expected[t];
    }
  }
  options.skippedTransforms = conv.skippedTransforms();
  options.stalePartitions = conv.stalePartitions();
  // Every set comes home once no level uses it.
  REQUIRE(conv.setNextIr(nullptr));
  const size_t settle = 4 * size_t(layout.level(layout.numLevels() - 1).period) + 2;
  std::vector<float> silence(b, 0.0f), sink(b * size_t(numOutputs));
  for (int s = 0; s < numSources; ++s) in[size_t(s)] = silence.data();
  for (int c = 0; c < numOutputs; ++c) o[size_t(c)] = sink.data() + size_t(c) * b;
  for (size_t k = 0; k < settle; ++k) {
    conv.process(in.data(), o.data());
    takeHome();
  }
  CHECK_FALSE(conv.swapping());
  for (char h : atHome) CHECK(h);
  const double rms = std::sqrt(energy / double((total - options.compareFrom) * size_t(numOutputs)));
  *worstSample = rms > 0.0 ? maxErr / rms : maxErr;
  return energy > 0.0 ? err / energy : err;
}

/// The same run as the pipeline makes it, against the same reference: silent levels' transforms
/// skipped (exact whenever no partition was left out; the onsets of the main test jump anywhere,
/// so some cases leave some out), and, when the IRs swap, swaps staggered over source groups
/// (16 blocks: level 0 in min(16, S) groups, a level of 4 blocks per chunk in min(4, S)).
void checkSkippingAndStaggered(const NonUniformLayout& layout,
                               const std::vector<std::vector<Signal>>& irs, int sources,
                               int outputs, const std::vector<Event>& events, size_t numBlocks,
                               int slot, std::mt19937& rng, bool swaps) {
  const double tol = tolerance(layout, sources);
  double worstSample = 0.0;
  RunOptions skipping;
  skipping.skipSilentLevels = true;
  const double relSkipping = runAndCompare(layout, irs, sources, outputs, events, numBlocks, slot,
                                           rng, &worstSample, skipping);
  INFO("skipping: " << skipping.skippedTransforms << " transforms skipped, "
                    << skipping.stalePartitions << " stale partitions, error "
                    << 10.0 * std::log10(std::max(relSkipping, 1e-300)) << " dB");
  if (skipping.stalePartitions == 0) CHECK(relSkipping < tol);
  if (!swaps) return;
  RunOptions staggered;
  staggered.swapSpread = 16;
  const double relStaggered = runAndCompare(layout, irs, sources, outputs, events, numBlocks, slot,
                                            rng, &worstSample, staggered);
  INFO("staggered swaps: error " << 10.0 * std::log10(std::max(relStaggered, 1e-300))
                                 << " dB, worst sample / RMS " << worstSample);
  CHECK(relStaggered < tol);
  CHECK(worstSample < 30.0 * std::sqrt(tol));
}

}  // namespace

TEST_CASE("Non-uniform layout: head at the block size, offsets 2 N - 2 B", "[convolver]") {
  NonUniformLayout layout(128, 144000, 8192);
  REQUIRE(layout.numLevels() == 4);
  const int sizes[] = {128, 512, 2048, 8192};
  for (int l = 0; l < 4; ++l) {
    const auto& lv = layout.level(l);
    CHECK(lv.partitionSize == sizes[l]);
    CHECK(lv.offset == (l == 0 ? 0u : size_t(2 * sizes[l] - 2 * 128)));
    // Each level reaches K = 2 partitions into the next one's segment (2 of 4 of its first).
    if (l < 3) {
      CHECK(lv.overlapPartitions == 2);
      CHECK(lv.offset + size_t((lv.numPartitions - 2) * lv.partitionSize) ==
            layout.level(l + 1).offset);
    }
  }
  CHECK(layout.level(3).overlapPartitions == 0);
  CHECK(layout.level(3).offset + size_t(layout.level(3).numPartitions) * 8192 >= 144000);
  CHECK(layout.totalPartitions() == 8 + 8 + 8 + 16);
  // The levels' shares of every sample sum to 1; outside the zones one level holds it alone.
  int shared = 0;
  for (size_t t = 0; t < 144000; ++t) {
    float sum = 0.0f, largest = 0.0f;
    for (int l = 0; l < 4; ++l) {
      sum += layout.share(l, t);
      largest = std::max(largest, layout.share(l, t));
    }
    CHECK(std::abs(sum - 1.0f) <= 1e-6f);
    shared += largest < 1.0f;
  }
  CHECK(shared == 2 * 128 + 2 * 512 + 2 * 2048);
  CHECK(NonUniformLayout(128, 144000, 8192, ConvolverLayout::Planning::kEstimate, 0)
            .totalPartitions() == 6 + 6 + 6 + 16);
  CHECK_THROWS_AS(NonUniformLayout(128, 100, 8192, ConvolverLayout::Planning::kEstimate, 5),
                  std::invalid_argument);

  CHECK_THROWS_AS(NonUniformLayout(0, 100), std::invalid_argument);
  CHECK_THROWS_AS(NonUniformLayout(8193, 100), std::invalid_argument);
  CHECK_THROWS_AS(NonUniformLayout(64, 0), std::invalid_argument);
  CHECK_THROWS_AS(NonUniformLayout(64, 100, 32), std::invalid_argument);
  NonUniformIrSet set(layout, 1, 1);
  std::vector<float> tooLong(144001, 0.0f);
  const float* p = tooLong.data();
  CHECK_THROWS_AS(set.prepare(0, &p, tooLong.size()), std::invalid_argument);
  CHECK_THROWS_AS(set.prepare(1, &p, 10), std::invalid_argument);
  NonUniformConvolver conv(layout, 2, 1);
  CHECK_FALSE(conv.setNextIr(&set));  // one source, the convolver has two
  // Staggered swaps: G_l = clamp(spread / m_l, 1, S); the spread is at least one block.
  CHECK_THROWS_AS(conv.setSwapSpread(0), std::invalid_argument);
  NonUniformConvolver many(layout, 6, 1);
  many.setSwapSpread(16);
  const int groups[] = {6, 4, 1, 1};  // periods 1, 4, 16, 64
  for (int l = 0; l < 4; ++l) CHECK(many.swapGroups(l) == groups[l]);
  // The last group crossfades (G_l - 1) m_l blocks after the first: 5 at level 0, 12 at 1.
  CHECK(many.swapDelayBlocks() == 12);
  NonUniformConvolver single(layout, 1, 1);
  single.setSwapSpread(16);
  CHECK(single.swapDelayBlocks() == 0);
}

namespace {

/// IR 0 from block 0, then swaps among IRs 0-2 and silence (-1) at random blocks of
/// [1, numBlocks), sometimes in consecutive blocks, never to the IR already playing.
std::vector<Event> randomSwaps(std::mt19937& rng, size_t numBlocks) {
  std::vector<Event> events = {{0, 0}};
  std::uniform_int_distribution<size_t> when(1, numBlocks - 1);
  std::vector<size_t> at;
  for (int i = 0; i < 6; ++i) at.push_back(when(rng));
  at.push_back(at[0] + 1 < numBlocks ? at[0] + 1 : at[0]);
  std::sort(at.begin(), at.end());
  at.erase(std::unique(at.begin(), at.end()), at.end());
  int last = 0;
  for (size_t k : at) {
    int next = int(rng() % 4) - 1;  // -1: silence
    if (next == last) next = (next + 2) % 3;
    events.push_back({k, next});
    last = next;
  }
  return events;
}

}  // namespace

namespace {

/// One layout against direct convolution: block, longest partition, sources, outputs, IR
/// length (samples), whether the IRs swap during the run, and whether they are silent before
/// random onsets (up to 60 %, at times all).
struct SwapCase {
  int block, maxPartition, sources, outputs;
  size_t irLength;
  bool swaps;
  bool onsets = false;
};

/// Runs each case against direct convolution (energy of the error and sample by sample) and
/// the skipping and staggered variants; prints the worst error.
void checkAgainstDirect(const std::vector<SwapCase>& cases, uint32_t seed) {
  std::mt19937 rng(seed);
  double worstDb = -1e9, worstMarginDb = -1e9;
  for (const SwapCase& cs : cases) {
    NonUniformLayout layout(cs.block, cs.irLength, cs.maxPartition);
    // Three IRs of different lengths (the last shorter than the layout: unused partitions).
    std::vector<std::vector<Signal>> irs;
    for (size_t len : {cs.irLength, cs.irLength - cs.irLength / 3, size_t(1) + cs.irLength / 9}) {
      std::vector<Signal> ir;
      for (int i = 0; i < cs.sources * cs.outputs; ++i) {
        ir.push_back(randomSignal(rng, len));
        if (!cs.onsets) continue;
        const size_t onset = rng() % 8 == 0 ? len : size_t(rng() % (len * 3 / 5 + 1));
        std::fill(ir.back().begin(), ir.back().begin() + long(onset), 0.0f);
      }
      irs.push_back(std::move(ir));
    }
    const size_t numBlocks = (cs.irLength + 3 * size_t(cs.maxPartition)) / size_t(cs.block) + 40;
    const std::vector<Event> events =
        cs.swaps ? randomSwaps(rng, numBlocks) : std::vector<Event>{{0, 0}};
    double worstSample = 0.0;
    const int slot = int(&cs - cases.data()) % NonUniformConvolver::kPhaseSlots;
    RunOptions options;  // onsets jump anywhere here: every chunk transformed (test below)
    const double rel = runAndCompare(layout, irs, cs.sources, cs.outputs, events, numBlocks, slot,
                                     rng, &worstSample, options);
    const double tol = tolerance(layout, cs.sources);
    const double db = 10.0 * std::log10(std::max(rel, 1e-300));
    worstDb = std::max(worstDb, db);
    worstMarginDb = std::max(worstMarginDb, db - 10.0 * std::log10(tol));
    INFO("B=" << cs.block << " slot " << slot << " maxPartition=" << cs.maxPartition << " levels "
              << layout.numLevels() << " L=" << cs.irLength << " error " << db << " dB");
    CHECK(rel < tol);
    // Sample by sample: rounding spreads over every sample, so no single sample may stray more
    // than 30 RMS-tolerances from the crossfade (a click at a swap or a partition boundary
    // would be a local error of the signal's own size, ~1e6 times larger).
    INFO("worst sample error / reference RMS " << worstSample);
    CHECK(worstSample < 30.0 * std::sqrt(tol));
    checkSkippingAndStaggered(layout, irs, cs.sources, cs.outputs, events, numBlocks, slot, rng,
                              cs.swaps);
  }
  std::printf(
      "non-uniform convolver vs direct: worst relative error energy %.1f dB, closest to "
      "tolerance %.1f dB\n",
      worstDb, worstMarginDb);
}

}  // namespace

TEST_CASE("Non-uniform convolution equals direct convolution, with IR swaps", "[convolver]") {
  checkAgainstDirect({{1, 16, 1, 1, 301, false},
                      {3, 48, 2, 1, 777, true},
                      {16, 256, 1, 2, 3001, false},
                      {16, 1024, 3, 2, 5003, true},
                      {64, 4096, 2, 2, 6007, true},
                      {100, 1600, 1, 1, 4999, true},
                      {128, 8192, 2, 2, 5555, true},
                      {37, 37, 1, 1, 1001, true},
                      // More sources than callbacks per chunk at the short levels, fewer at the
                      // long ones: the sources' transforms share callbacks.
                      {16, 256, 7, 1, 1500, true},
                      {16, 1024, 4, 2, 5003, true, true}},
                     20261122);
}

TEST_CASE("Non-uniform convolution equals direct convolution: IRs of 9,000-20,000 samples",
          "[convolver][heavy]") {
  checkAgainstDirect({{256, 8192, 1, 2, 9001, true},
                      {512, 8192, 2, 1, 20011, true},
                      {64, 8192, 3, 1, 20011, true, true}},
                     20261127);
}

TEST_CASE("Non-uniform convolver: levels' last callbacks never coincide", "[convolver]") {
  // Block 16 with a 20 s IR gives levels up to m = 512; hybrid rendering runs two convolvers
  // (slots 0 and 1) in one callback. Over 4 periods of the longest level, no block may hold
  // the last callback (k + phi = m - 2 mod m) of two tail levels 1..kStaggeredLevels.
  NonUniformLayout layout(16, 960000, 8192);
  REQUIRE(layout.numLevels() > NonUniformConvolver::kStaggeredLevels);
  std::vector<std::unique_ptr<NonUniformConvolver>> convs;
  for (int slot = 0; slot < NonUniformConvolver::kPhaseSlots; ++slot)
    convs.push_back(std::make_unique<NonUniformConvolver>(layout, 1, 1, slot));
  const int maxPeriod = layout.level(layout.numLevels() - 1).period;
  int worst = 0;
  for (long long k = 0; k < 4LL * maxPeriod; ++k) {
    int finishing = 0;
    for (const auto& conv : convs)
      for (int l = 1; l <= NonUniformConvolver::kStaggeredLevels; ++l) {
        const long long m = layout.level(l).period;
        finishing += (k + conv->levelPhase(l)) % m == m - 2 ? 1 : 0;
      }
    worst = std::max(worst, finishing);
  }
  CHECK(worst == 1);
  CHECK_THROWS_AS(NonUniformConvolver(layout, 1, 1, NonUniformConvolver::kPhaseSlots),
                  std::invalid_argument);
}

TEST_CASE("Non-uniform convolver: a steady IR convolves exactly across the shared zones",
          "[convolver]") {
  // Against the whole IR's direct convolution (no shares in the reference): where levels
  // overlap their shares must sum to 1. Layouts with odd block sizes, a partition cap at which
  // the size only doubles, a single level, and IRs that end inside a zone.
  struct Case {
    int block;
    size_t irSamples;
    int maxPartition;
  };
  const Case cases[] = {{64, 6007, 4096}, {7, 3001, 56},   {100, 9000, 800},
                        {64, 390, 4096},  {64, 400, 4096}, {16, 10, 4096}};
  std::mt19937 rng(20261203);
  for (const Case& c : cases) {
    const NonUniformLayout layout(c.block, c.irSamples, c.maxPartition);
    const Signal h = randomSignal(rng, c.irSamples);
    NonUniformIrSet set(layout, 1, 1);
    const float* hp = h.data();
    set.prepare(0, &hp, h.size());
    NonUniformConvolver conv(layout, 1, 1);
    REQUIRE(conv.setNextIr(&set));
    // A slow level takes its first IR at its first chunk, fading in from silence once sound
    // has entered: silence first, as long as the slowest level's chunk.
    const size_t lead = size_t(layout.level(layout.numLevels() - 1).period) * size_t(c.block);
    const size_t blocks = (2 * c.irSamples + lead) / size_t(c.block) + 8;
    Signal x = randomSignal(rng, blocks * size_t(c.block));
    std::fill(x.begin(), x.begin() + long(lead), 0.0f);
    Signal y(x.size());
    for (size_t k = 0; k < blocks; ++k) {
      const float* in = x.data() + k * size_t(c.block);
      float* out = y.data() + k * size_t(c.block);
      conv.process(&in, &out);
    }
    const std::vector<double> expected = segmentConvolution(x, h, 0, h.size());
    double err = 0.0, energy = 0.0;
    for (size_t t = 0; t < y.size(); ++t) {
      err += (y[t] - expected[t]) * (y[t] - expected[t]);
      energy += expected[t] * expected[t];
    }
    INFO("block " << c.block << ", IR " << c.irSamples << ", cap " << c.maxPartition << ": "
                  << layout.numLevels() << " levels, error "
                  << 10 * std::log10(std::max(err / energy, 1e-300)) << " dB");
    CHECK(err / energy < tolerance(layout, 1));
  }
}

namespace {

/// One IR per source (one output channel), random, silent before that source's onset.
std::vector<Signal> irsWithOnsets(std::mt19937& rng, size_t length,
                                  std::initializer_list<size_t> onsets) {
  std::vector<Signal> irs;
  for (size_t onset : onsets) {
    irs.push_back(randomSignal(rng, length));
    std::fill(irs.back().begin(), irs.back().begin() + long(onset), 0.0f);
  }
  return irs;
}

}  // namespace

TEST_CASE("Non-uniform convolver: levels a source is silent at skip their transforms",
          "[convolver]") {
  // B = 64, levels [0, 512), [384, 2432) and [1920, 6007) samples (each but the last reaching
  // two partitions into the next): level 0 skips a source whose sets all start sounding at or
  // after 1024, level 1 at or after 4480 (one segment beyond each level's end); the last level
  // transforms every source that sounds.
  std::mt19937 rng(20261125);
  const NonUniformLayout layout(64, 6007, 4096);
  REQUIRE(layout.numLevels() == 3);
  const double tol = tolerance(layout, 2);
  // Source 0 approaches: its onset drifts from 5000 to 100 samples over five sets 60 blocks
  // apart, each step within the margin (level 1 resumes at 4000 and sounds from 2000, level 0
  // resumes at 900 and sounds from 100); source 1 sounds from its first sample throughout.
  const size_t drift[] = {5000, 4000, 2000, 900, 100};
  std::vector<std::vector<Signal>> irs;
  std::vector<Event> events;
  for (size_t i = 0; i < std::size(drift); ++i) {
    irs.push_back(irsWithOnsets(rng, 6007, {drift[i], 0}));
    events.push_back({i * 60, int(i)});
  }
  double worst = 0.0;
  RunOptions drifting;
  drifting.skipSilentLevels = true;
  double rel = runAndCompare(layout, irs, 2, 1, events, 400, 0, rng, &worst, drifting);
  INFO("drift: error " << 10 * std::log10(std::max(rel, 1e-300)) << " dB, "
                       << drifting.skippedTransforms << " transforms skipped, "
                       << drifting.stalePartitions << " stale partitions");
  CHECK(drifting.skippedTransforms > 0);
  CHECK(drifting.stalePartitions == 0);
  CHECK(rel < tol);
  CHECK(worst < 30.0 * std::sqrt(tol));

  // A jump (a teleport) from onset 5000 to 0 at block 100: the partitions whose input chunk
  // was skipped (levels 0 and 1) are left out and counted; once every level has transformed
  // P_l + 2 chunks again the output is exact. Compared over the whole run the loss shows.
  irs = {irsWithOnsets(rng, 6007, {5000, 0}), irsWithOnsets(rng, 6007, {0, 0})};
  events = {{0, 0}, {100, 1}};
  size_t settle = 0;
  for (int l = 0; l < layout.numLevels(); ++l)
    settle = std::max(settle,
                      size_t(layout.level(l).numPartitions + 2) * size_t(layout.level(l).period));
  const size_t blocks = 100 + settle + 100;
  RunOptions after;
  after.skipSilentLevels = true;
  after.compareFrom = (100 + settle) * 64;
  rel = runAndCompare(layout, irs, 2, 1, events, blocks, 1, rng, &worst, after);
  INFO("after the jump and " << settle << " blocks: error "
                             << 10 * std::log10(std::max(rel, 1e-300)) << " dB, "
                             << after.stalePartitions << " stale partitions");
  CHECK(after.stalePartitions > 0);
  CHECK(rel < tol);
  CHECK(worst < 30.0 * std::sqrt(tol));
  RunOptions whole;
  whole.skipSilentLevels = true;
  rel = runAndCompare(layout, irs, 2, 1, events, blocks, 1, rng, &worst, whole);
  CHECK(whole.stalePartitions == after.stalePartitions);
  CHECK(rel > tol);
}

TEST_CASE("Non-uniform convolver: a source silent in one set may sound anywhere in the next",
          "[convolver]") {
  // Source 0's IR is all zeros (an occluded source no ray reached) and then sounds from its
  // first sample: no level may have skipped it, so nothing is left out and the output is
  // exact over the whole run.
  std::mt19937 rng(20261126);
  const NonUniformLayout layout(64, 6007, 4096);
  const std::vector<std::vector<Signal>> irs = {irsWithOnsets(rng, 6007, {6007, 0}),
                                                irsWithOnsets(rng, 6007, {0, 0})};
  const std::vector<Event> events = {{0, 0}, {100, 1}};
  RunOptions options;
  options.skipSilentLevels = true;
  double worst = 0.0;
  const double rel = runAndCompare(layout, irs, 2, 1, events, 400, 0, rng, &worst, options);
  INFO("error " << 10 * std::log10(std::max(rel, 1e-300)) << " dB, " << options.stalePartitions
                << " stale partitions");
  CHECK(options.stalePartitions == 0);
  CHECK(rel < tolerance(layout, 2));
}
