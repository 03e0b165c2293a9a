// PartitionedConvolver against brute-force direct convolution in double precision, IR
// crossfades against the crossfade of two direct convolutions.
#include "audio/convolver.h"

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <random>
#include <stdexcept>
#include <vector>

#include "tests/audio/convolution_reference.h"

using namespace dpc::audio;

namespace {

using dpc::test::Signal;
using Reference = std::vector<double>;

using dpc::test::randomSignal;

/// y[n] = sum_k h[k] x[n - k], n < x.size(), in double precision.
Reference directConvolution(const Signal& x, const Signal& h) {
  return dpc::test::segmentConvolution(x, h, 0, h.size());
}

/// Runs x (a whole number of blocks) through conv; one signal per output.
void runBlocks(PartitionedConvolver& conv, const Signal& x, size_t firstBlock, size_t numBlocks,
               std::vector<Signal>& out) {
  const size_t b = size_t(conv.blockSize());
  std::vector<float*> ptrs(size_t(conv.numOutputs()));
  for (size_t k = firstBlock; k < firstBlock + numBlocks; ++k) {
    for (size_t c = 0; c < ptrs.size(); ++c) ptrs[c] = out[c].data() + k * b;
    conv.process(x.data() + k * b, ptrs.data());
  }
}

/// sum (y - ref)^2 / sum ref^2 over [begin, end).
double relativeErrorEnergy(const Signal& y, const Reference& ref, size_t begin, size_t end) {
  double err = 0.0, energy = 0.0;
  for (size_t n = begin; n < end; ++n) {
    const double d = double(y[n]) - ref[n];
    err += d * d;
    energy += ref[n] * ref[n];
  }
  return energy > 0.0 ? err / energy : err;
}

double toDb(double energyRatio) {
  return 10.0 * std::log10(std::max(energyRatio, 1e-300));
}

/// Tolerance on the relative error energy. Each output sample is, in effect, the inner product
/// of the IR with the input computed through float FFTs: rounding errors of relative size
/// u = 2^-24 enter in the forward transforms (log2(2B) stages each), in the P-term complex
/// multiply-accumulate per bin and in the inverse transform. Treating them as independent,
/// the relative error energy is about u^2 * (c1 log2(2B) + c2 P); we allow
/// 64 u^2 (log2(2B) + P) (so relative RMS error 8 u sqrt(log2(2B) + P), a margin of ~10x over
/// the measured levels), and never more than -100 dB (1e-10).
double tolerance(int blockSize, size_t irSamples) {
  const double u = std::ldexp(1.0, -24);
  const double partitions = std::ceil(double(irSamples) / double(blockSize));
  const double bound = 64.0 * u * u * (std::log2(2.0 * blockSize) + partitions);
  return std::min(bound, 1e-10);
}

/// A one-source, one-output convolver holding a random IR of `length` samples drawn from rng,
/// and the input run through it with its output.
struct RandomIrConvolver {
  RandomIrConvolver(std::mt19937& rng, int block, size_t length)
      : h(randomSignal(rng, length)), layout(block, length), spectra(layout, 1), conv(layout, 1) {
    const float* hp = h.data();
    spectra.prepare(&hp, h.size());
    REQUIRE(conv.setNextIr(&spectra));
  }
  /// `blocks` blocks of new random input from rng; the output keeps what it holds (zeros the
  /// first time).
  void newInput(std::mt19937& rng, size_t blocks) {
    x = randomSignal(rng, blocks * size_t(layout.blockSize()));
    out.resize(1);
    out[0].resize(x.size(), 0.0f);
  }
  void run(size_t firstBlock, size_t numBlocks) { runBlocks(conv, x, firstBlock, numBlocks, out); }
  /// The output's relative error energy against the direct convolution of x and h, from sample
  /// `begin` to the end.
  double errorFrom(size_t begin) const {
    return relativeErrorEnergy(out[0], directConvolution(x, h), begin, x.size());
  }
  double allowedError() const { return tolerance(layout.blockSize(), h.size()); }
  Signal h;
  ConvolverLayout layout;
  IrSpectra spectra;
  PartitionedConvolver conv;
  Signal x;
  std::vector<Signal> out;
};

/// w[n] = (n + 1) / B crossfade of a and b over [begin, begin + B).
Reference crossfade(const Reference& a, const Reference& b, size_t begin, size_t blockSize) {
  Reference y(blockSize);
  for (size_t n = 0; n < blockSize; ++n) {
    const double w = double(n + 1) / double(blockSize);
    y[n] = (1.0 - w) * a[begin + n] + w * b[begin + n];
  }
  return y;
}

}  // namespace

TEST_CASE("Partitioned convolution equals direct convolution", "[convolver]") {
  std::mt19937 rng(20240611);
  std::vector<int> blockSizes = {1, 2, 3, 7, 16, 17, 64, 97, 128, 250, 256, 509, 1024, 1031, 1500};
  std::uniform_int_distribution<int> randomBlock(1, 1500);
  for (int i = 0; i < 5; ++i) blockSizes.push_back(randomBlock(rng));

  double worstDb = -1e9, worstMarginDb = -1e9;  // error, and error relative to tolerance
  for (int b : blockSizes) {
    const size_t ub = size_t(b);
    std::uniform_int_distribution<size_t> mid(2 * ub, 8 * ub);
    // 1 sample, shorter than, equal to and just over B, several partitions, many partitions
    // (capped so that the double-precision reference stays fast).
    const std::vector<size_t> irLengths = {
        1,      ub / 2 + 1, ub,
        ub + 1, mid(rng),   std::min<size_t>(std::max<size_t>(40 * ub, 200), 12000)};
    for (size_t irLength : irLengths) {
      // Layout capacity sometimes larger than the IR: the FDL then has unused partitions.
      const size_t capacity = irLength + (rng() % 2 ? 0 : size_t(rng() % (3 * ub + 1)));
      ConvolverLayout layout(b, capacity);
      IrSpectra spectra(layout, 1);
      const Signal h = randomSignal(rng, irLength);
      const float* hp = h.data();
      spectra.prepare(&hp, h.size());

      const size_t numBlocks = (irLength + 2 * ub) / ub + 2 + rng() % 3;
      const Signal x = randomSignal(rng, numBlocks * ub);
      const Reference ref = directConvolution(x, h);

      PartitionedConvolver conv(layout, 1);
      std::vector<Signal> out(1, Signal(x.size(), 0.0f));
      // Set before any sound: the IR applies from the first sample (no fade-in from silence).
      REQUIRE(conv.setNextIr(&spectra));
      runBlocks(conv, x, 0, numBlocks, out);
      CHECK(conv.takeRetired() == nullptr);  // nothing was current before

      const double rel = relativeErrorEnergy(out[0], ref, 0, x.size());
      worstDb = std::max(worstDb, toDb(rel));
      worstMarginDb = std::max(worstMarginDb, toDb(rel) - toDb(tolerance(b, irLength)));
      INFO("B=" << b << " L=" << irLength << " capacity=" << capacity << " error " << toDb(rel)
                << " dB, tolerance " << toDb(tolerance(b, irLength)) << " dB");
      CHECK(rel < tolerance(b, irLength));
    }
  }
  std::printf(
      "convolver vs direct: worst relative error energy %.1f dB, closest to tolerance %.1f dB\n",
      worstDb, worstMarginDb);
}

TEST_CASE("IR change crossfades the two full convolutions over one block", "[convolver]") {
  std::mt19937 rng(7);
  for (int b : {1, 37, 64, 250}) {
    const size_t ub = size_t(b);
    const Signal hA = randomSignal(rng, 3 * ub + 5);
    const Signal hB = randomSignal(rng, ub / 2 + 1);
    const Signal hC = randomSignal(rng, 5 * ub);
    ConvolverLayout layout(b, 5 * ub + 5);
    IrSpectra sa(layout, 1), sb(layout, 1), sc(layout, 1);
    const float* pa = hA.data();
    const float* pb = hB.data();
    const float* pc = hC.data();
    sa.prepare(&pa, hA.size());
    sb.prepare(&pb, hB.size());
    sc.prepare(&pc, hC.size());

    const size_t numBlocks = 20;
    const Signal x = randomSignal(rng, numBlocks * ub);
    const Reference refA = directConvolution(x, hA);
    const Reference refB = directConvolution(x, hB);
    const Reference refC = directConvolution(x, hC);

    // Expected output: blocks 0..5 A (the first IR over a silent history starts at once),
    // block 6 A -> C (B was replaced before the swap), blocks 7..11 C, block 12 C -> silence,
    // then silence.
    Reference expected(x.size(), 0.0);
    const Reference silence(x.size(), 0.0);
    auto put = [&](const Reference& block, size_t k) {
      std::copy(block.begin(), block.end(), expected.begin() + std::ptrdiff_t(k * ub));
    };
    for (size_t k = 0; k < 6; ++k)
      put(Reference(refA.begin() + k * ub, refA.begin() + (k + 1) * ub), k);
    put(crossfade(refA, refC, 6 * ub, ub), 6);
    for (size_t k = 7; k < 12; ++k)
      put(Reference(refC.begin() + k * ub, refC.begin() + (k + 1) * ub), k);
    put(crossfade(refC, silence, 12 * ub, ub), 12);

    PartitionedConvolver conv(layout, 1);
    std::vector<Signal> out(1, Signal(x.size(), 0.0f));
    REQUIRE(conv.setNextIr(&sa));
    CHECK(conv.hasPending());
    runBlocks(conv, x, 0, 1, out);
    CHECK(conv.currentIr() == &sa);
    CHECK_FALSE(conv.hasPending());
    CHECK(conv.takeRetired() == nullptr);
    runBlocks(conv, x, 1, 5, out);

    REQUIRE(conv.setNextIr(&sb));
    REQUIRE(conv.setNextIr(&sc));  // newest wins; B is retired at once, never used
    CHECK(conv.pendingIr() == &sc);
    CHECK(conv.takeRetired() == &sb);
    CHECK(conv.takeRetired() == nullptr);
    runBlocks(conv, x, 6, 1, out);
    CHECK(conv.currentIr() == &sc);
    CHECK(conv.takeRetired() == &sa);  // swapped out after its crossfade
    CHECK(conv.takeRetired() == nullptr);
    runBlocks(conv, x, 7, 5, out);

    REQUIRE(conv.setNextIr(nullptr));  // fade out to silence
    runBlocks(conv, x, 12, numBlocks - 12, out);
    CHECK(conv.currentIr() == nullptr);
    CHECK(conv.takeRetired() == &sc);
    CHECK(conv.takeRetired() == nullptr);

    const double tol = tolerance(b, 5 * ub + 5);
    auto blockError = [&](size_t k) {
      return relativeErrorEnergy(out[0], expected, k * ub, (k + 1) * ub);
    };
    INFO("B=" << b << " first block " << toDb(blockError(0)) << " dB, A->C " << toDb(blockError(6))
              << " dB, fade-out " << toDb(blockError(12)) << " dB, whole "
              << toDb(relativeErrorEnergy(out[0], expected, 0, x.size())) << " dB");
    CHECK(blockError(0) < tol);
    CHECK(blockError(6) < tol);
    CHECK(blockError(12) < tol);
    CHECK(relativeErrorEnergy(out[0], expected, 0, 12 * ub) < tol);
    // Silence after the fade-out is exactly zero.
    CHECK(std::all_of(out[0].begin() + std::ptrdiff_t(13 * ub), out[0].end(),
                      [](float v) { return v == 0.0f; }));
  }
}

TEST_CASE("The first IR fades in once sound has entered, at once before", "[convolver]") {
  // An impulse at the first sample through h: an IR set before it is heard gives h from that
  // sample on (an offline render's first IR, and its sound's onset); set one block after
  // sound has entered (a live engine's first IR), it fades in over that block from silence,
  // w[n] = (n + 1) / B, as every IR change does, so no history bursts in. The oracle is h.
  const int b = 64;
  const size_t ub = size_t(b);
  std::mt19937 rng(5);
  const Signal h = randomSignal(rng, 3 * ub);
  ConvolverLayout layout(b, h.size());
  IrSpectra spectra(layout, 1);
  const float* hp = h.data();
  spectra.prepare(&hp, h.size());
  Signal x(4 * ub, 0.0f);
  x[0] = 1.0f;
  for (const bool late : {false, true}) {
    PartitionedConvolver conv(layout, 1);
    std::vector<Signal> out(1, Signal(x.size(), 0.0f));
    if (!late) REQUIRE(conv.setNextIr(&spectra));
    runBlocks(conv, x, 0, 1, out);
    if (late) REQUIRE(conv.setNextIr(&spectra));
    runBlocks(conv, x, 1, 3, out);
    double worst = 0.0;
    for (size_t n = 0; n < x.size(); ++n) {
      double expected = n < h.size() ? h[n] : 0.0;
      if (late) expected *= n < ub ? 0.0 : n < 2 * ub ? double(n - ub + 1) / double(ub) : 1.0;
      worst = std::max(worst, std::abs(double(out[0][n]) - expected));
    }
    INFO((late ? "set after sound entered" : "set before any sound") << ": worst " << worst);
    CHECK(worst < 1e-5);  // float FFT rounding of unit-scale samples; the fade is 1/B = 0.016
  }
}

TEST_CASE("Setting the current IR again is no change", "[convolver]") {
  std::mt19937 rng(11);
  RandomIrConvolver f(rng, 48, 100);
  f.newInput(rng, 10);
  f.run(0, 4);
  REQUIRE(f.conv.setNextIr(&f.spectra));
  CHECK_FALSE(f.conv.hasPending());
  f.run(4, 6);
  CHECK(f.conv.takeRetired() == nullptr);     // the spectra are still current: never retired
  CHECK(f.errorFrom(48) < f.allowedError());  // from the second block on
}

TEST_CASE("Two outputs with different IRs match their own direct convolutions", "[convolver]") {
  std::mt19937 rng(3);
  for (int b : {5, 128, 333}) {
    const size_t ub = size_t(b);
    const Signal left = randomSignal(rng, 4 * ub + 3);
    const Signal right = randomSignal(rng, ub / 3 + 1);
    ConvolverLayout layout(b, left.size());
    IrSpectra spectra(layout, 2);
    const float* irs[2] = {left.data(), right.data()};
    // Channels of one IrSpectra share n; the shorter IR is zero-padded to the same length.
    Signal rightPadded = right;
    rightPadded.resize(left.size(), 0.0f);
    irs[1] = rightPadded.data();
    spectra.prepare(irs, left.size());

    const size_t numBlocks = 12;
    const Signal x = randomSignal(rng, numBlocks * ub);
    PartitionedConvolver conv(layout, 2);
    REQUIRE(conv.setNextIr(&spectra));
    // processAdd on top of a known signal: the result must be that signal plus the convolution.
    const Signal bias0 = randomSignal(rng, x.size());
    const Signal bias1 = randomSignal(rng, x.size());
    std::vector<Signal> out = {bias0, bias1};
    std::vector<float*> ptrs(2);
    for (size_t k = 0; k < numBlocks; ++k) {
      ptrs[0] = out[0].data() + k * ub;
      ptrs[1] = out[1].data() + k * ub;
      conv.processAdd(x.data() + k * ub, ptrs.data());
    }
    const Reference refL = directConvolution(x, left);
    const Reference refR = directConvolution(x, right);
    Signal convL(x.size()), convR(x.size());
    for (size_t n = 0; n < x.size(); ++n) {
      convL[n] = out[0][n] - bias0[n];
      convR[n] = out[1][n] - bias1[n];
    }
    // Subtracting the bias adds up to u |bias| per sample: allow for it (bias energy ~ output
    // energy, so a few u^2 more).
    const double eL = relativeErrorEnergy(convL, refL, 0, x.size());
    const double eR = relativeErrorEnergy(convR, refR, 0, x.size());
    INFO("B=" << b << " left " << toDb(eL) << " dB, right " << toDb(eR) << " dB");
    CHECK(eL < tolerance(b, left.size()));
    CHECK(eR < tolerance(b, left.size()));
    // The outputs really differ (a shared-IR bug could not pass both checks, but be explicit).
    CHECK(relativeErrorEnergy(convR, refL, 0, x.size()) > 0.1);
  }
}

TEST_CASE("Re-preparing a spectrum with a shorter IR forgets the longer one", "[convolver]") {
  std::mt19937 rng(5);
  const int b = 32;
  ConvolverLayout layout(b, 10 * 32);
  const Signal longIr = randomSignal(rng, 10 * 32);
  const Signal shortIr = randomSignal(rng, 40);
  IrSpectra s(layout, 1);
  const float* p = longIr.data();
  s.prepare(&p, longIr.size());
  CHECK(s.channel(0).activePartitions() == 10);
  p = shortIr.data();
  s.prepare(&p, shortIr.size());
  CHECK(s.channel(0).activePartitions() == 2);

  PartitionedConvolver conv(layout, 1);
  REQUIRE(conv.setNextIr(&s));
  const Signal x = randomSignal(rng, 30 * 32);
  std::vector<Signal> out(1, Signal(x.size(), 0.0f));
  runBlocks(conv, x, 0, 30, out);
  const Reference ref = directConvolution(x, shortIr);
  CHECK(relativeErrorEnergy(out[0], ref, 32, x.size()) < tolerance(b, shortIr.size()));

  // An empty IR is silence.
  s.prepare(&p, 0);
  CHECK(s.channel(0).activePartitions() == 0);
  runBlocks(conv, x, 0, 30, out);
  CHECK(std::all_of(out[0].begin(), out[0].end(), [](float v) { return v == 0.0f; }));
}

TEST_CASE("reset() clears the input history", "[convolver]") {
  std::mt19937 rng(9);
  RandomIrConvolver f(rng, 20, 90);
  f.newInput(rng, 10);  // noise, to be forgotten
  f.run(0, 10);
  f.conv.reset();
  CHECK(f.conv.currentIr() == &f.spectra);
  f.newInput(rng, 10);
  f.run(0, 10);
  CHECK(f.errorFrom(0) < f.allowedError());
}

TEST_CASE("Errors: sizes, capacity, mismatched spectra, full retired list", "[convolver]") {
  CHECK_THROWS_AS(ConvolverLayout(0, 10), std::invalid_argument);
  CHECK_THROWS_AS(ConvolverLayout(-3, 10), std::invalid_argument);
  CHECK_THROWS_AS(ConvolverLayout(16, 0), std::invalid_argument);

  ConvolverLayout layout(16, 100);
  CHECK(layout.numPartitions() == 7);
  CHECK(layout.maxIrSamples() == 112);
  CHECK(layout.binStride() % 16 == 0);
  CHECK(layout.binStride() >= 17);
  CHECK_THROWS_AS(IrSpectra(layout, 0), std::invalid_argument);
  CHECK_THROWS_AS(PartitionedConvolver(layout, 0), std::invalid_argument);

  IrSpectra mono(layout, 1);
  const Signal ir(113, 0.5f);
  const float* p = ir.data();
  CHECK_THROWS_AS(mono.prepare(&p, 113), std::invalid_argument);
  CHECK_NOTHROW(mono.prepare(&p, 112));

  PartitionedConvolver stereo(layout, 2);
  CHECK_FALSE(stereo.setNextIr(&mono));  // 1 channel into 2 outputs
  CHECK_FALSE(stereo.hasPending());
  ConvolverLayout other(17, 100);
  IrSpectra otherStereo(other, 2);
  CHECK_FALSE(stereo.setNextIr(&otherStereo));  // different block size
  ConvolverLayout longer(16, 200);
  IrSpectra longerStereo(longer, 2);
  CHECK_FALSE(stereo.setNextIr(&longerStereo));  // different partition count

  // Without takeRetired() the retired list fills up; setNextIr then refuses instead of
  // overflowing, and every replaced IR comes back, oldest first.
  PartitionedConvolver conv(layout, 1);
  std::vector<IrSpectra> many;
  many.reserve(20);
  for (int i = 0; i < 20; ++i) many.emplace_back(layout, 1);
  int accepted = 0;
  for (auto& s : many) {
    if (!conv.setNextIr(&s)) break;
    ++accepted;
  }
  CHECK(accepted == PartitionedConvolver::kRetiredCapacity);
  CHECK(conv.pendingIr() == &many[size_t(accepted - 1)]);
  for (int i = 0; i < accepted - 1; ++i) CHECK(conv.takeRetired() == &many[size_t(i)]);
  CHECK(conv.takeRetired() == nullptr);
  CHECK(conv.setNextIr(&many[19]));
  CHECK(conv.takeRetired() == &many[size_t(accepted - 1)]);
}

TEST_CASE("The two-output multiply-accumulate equals two one-output calls bit for bit",
          "[convolver]") {
  // Stereo and binaural convolution take the fused form; renders stay bit-identical to the
  // one-output form only if every bin's float operations are the same.
  std::mt19937 rng(20261125);
  std::uniform_real_distribution<float> u(-1.f, 1.f);
  const size_t n = 144;  // a 128-sample block's bin stride
  const auto random = [&] {
    std::vector<float> v(2 * n);
    for (float& x : v) x = u(rng);
    return v;
  };
  const std::vector<float> x = random(), h0 = random(), h1 = random();
  std::vector<float> a0 = random(), a1 = random();
  std::vector<float> b0 = a0, b1 = a1;
  for (int repeat = 0; repeat < 3; ++repeat) {
    detail::multiplyAccumulate(a0.data(), a0.data() + n, x.data(), x.data() + n, h0.data(),
                               h0.data() + n, n);
    detail::multiplyAccumulate(a1.data(), a1.data() + n, x.data(), x.data() + n, h1.data(),
                               h1.data() + n, n);
    detail::multiplyAccumulate2(b0.data(), b0.data() + n, b1.data(), b1.data() + n, x.data(),
                                x.data() + n, h0.data(), h0.data() + n, h1.data(), h1.data() + n,
                                n);
  }
  CHECK(a0 == b0);
  CHECK(a1 == b1);
  CHECK(a0 != a1);
}
