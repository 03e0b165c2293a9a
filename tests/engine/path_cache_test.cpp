#include "engine/path_cache.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <vector>

#include "common/random.h"
#include "testing/test_util.h"

using dpc::test::identical;

using namespace dpc;

namespace {

constexpr float kC = 343.f;

PathHit hit(uint64_t key, float intensity, float length) {
  PathHit h;
  h.key = key;
  h.intensity = Bands(intensity);
  h.length = length;
  h.direction = {1.f, 0.f, 0.f};
  return h;
}

EnergyResponse frame(DiffusePathCache& cache, const std::vector<PathHit>& hits, uint64_t n) {
  FrameGroups g;
  for (const PathHit& h : hits) g.add(h);
  EnergyResponse out(1.0, 1e-3);
  cache.endFrame(g, n, kC, out);
  return out;
}

/// Energy in band 0 at the bin of delay r / c.
float at(const EnergyResponse& e, float r) {
  return e.bins()[size_t(r / kC / 1e-3)][0];
}

}  // namespace

TEST_CASE("Seed DPC: eq. 3.2-3.4 on a hand-built hit sequence, ageing out at tau", "[dpc]") {
  const double period = 0.1, tau = 0.3;  // lifetime = 3 frames
  DiffusePathCache cache(DpcWeighting::kSeed, tau, period);
  REQUIRE(cache.lifetimeFrames() == 3);
  const uint64_t N = 1000;
  // Frame 0: two hits of path 7 (I = 2 and 4, r = 10 m and 12 m), one of path 9.
  auto e0 = frame(cache, {hit(7, 2.f, 10.f), hit(9, 1.f, 30.f), hit(7, 4.f, 12.f)}, N);
  // eta = 2, mu = N, I_hat = 6, r_hat = 22: I_bar = 6 / N at r_bar = 11 m (eq. 3.2, 3.3).
  CHECK(at(e0, 11.f) == Approx(6.0 / N));
  CHECK(at(e0, 30.f) == Approx(1.0 / N));
  CHECK(cache.entryCount() == 2);
  // Frame 1: path 7 again (I = 3, r = 13): eta = 3, mu = 2N, I_hat = 9, r_hat = 35.
  auto e1 = frame(cache, {hit(7, 3.f, 13.f)}, N);
  CHECK(at(e1, 35.f / 3.f) == Approx(9.0 / (2 * N)));
  CHECK(at(e1, 30.f) == Approx(1.0 / (2 * N)));  // path 9 not hit: mu grows, I_bar falls
  // Frame 2: nothing. Both entries are read out a third time, then are tau old and go.
  auto e2 = frame(cache, {}, N);
  CHECK(at(e2, 35.f / 3.f) == Approx(9.0 / (3 * N)));
  CHECK(at(e2, 30.f) == Approx(1.0 / (3 * N)));
  CHECK(cache.entryCount() == 0);
  // Frame 3: path 7 comes back as a new entry (eta = 1, mu = N).
  auto e3 = frame(cache, {hit(7, 5.f, 10.f)}, N);
  CHECK(at(e3, 10.f) == Approx(5.0 / N));
  CHECK(e3.total()[0] == Approx(5.0 / N));
}

TEST_CASE("EMA DPC: moving average of per-frame estimates, start-up normalised", "[dpc]") {
  const double period = 0.1, tau = 0.5;
  DiffusePathCache cache(DpcWeighting::kEma, tau, period);
  const double a = 1.0 - std::exp(-period / tau);
  REQUIRE(cache.emaCoefficient() == Approx(a));
  const uint64_t N = 100;
  // Frame 0: one hit I = 1 at 20 m. Start-up normalisation 1 - (1-a) = a: estimate = 1/N.
  auto e0 = frame(cache, {hit(3, 1.f, 20.f)}, N);
  CHECK(at(e0, 20.f) == Approx(1.0 / N));
  // Frame 1: no hit. EMA = a (1-a) / N, normalised by 1 - (1-a)^2.
  auto e1 = frame(cache, {}, N);
  CHECK(at(e1, 20.f) == Approx(a * (1 - a) / N / (1 - (1 - a) * (1 - a))).epsilon(1e-5));
  // Frame 2: hit at 22 m: delay = EMA of r_f over EMA of eta_f.
  auto e2 = frame(cache, {hit(3, 1.f, 22.f)}, N);
  const double w0 = a * (1 - a) * (1 - a), w2 = a;
  const double rBar = (w0 * 20 + w2 * 22) / (w0 + w2);
  CHECK(at(e2, float(rBar)) > 0.f);
  // The entry disappears once its weight is below the drop fraction.
  for (uint32_t f = 0; f < cache.lifetimeFrames() + 1; ++f) frame(cache, {}, N);
  CHECK(cache.entryCount() == 0);
}

TEST_CASE("tau = 0: every DPC weighting equals plain path tracing bit for bit", "[dpc]") {
  for (DpcWeighting w : {DpcWeighting::kSeed, DpcWeighting::kEma, DpcWeighting::kWindow}) {
    DiffusePathCache cache(w, 0.0, 1.0 / 15);
    PathTracingEstimator pt;
    Rng rng(5, 5);
    for (int f = 0; f < 10; ++f) {
      FrameGroups g;
      for (int i = 0; i < 500; ++i)
        g.add(hit(rng.nextU32() % 60, rng.uniform() * 1e-3f, 3.f + 300.f * rng.uniform()));
      EnergyResponse a(1.0, 1e-3), b(1.0, 1e-3);
      cache.endFrame(g, 4096, kC, a);
      pt.endFrame(g, 4096, kC, b);
      REQUIRE(identical(a, b));
      // Window entries leave when their one-frame window moves on, at the next frame.
      if (w != DpcWeighting::kWindow) REQUIRE(cache.entryCount() == 0);
    }
  }
}

TEST_CASE("Window DPC: retiring a frame never leaves a negative band energy", "[dpc]") {
  // One path hit every frame in band 0 (so its entry stays), and in band 7 with 1 in frame 0
  // and 1e-8 in frame 1 only. In float, (1 + 1e-8) - 1 - 1e-8 is -1e-8, not 0: subtracting
  // retired terms must not leave such residue (energy is a sum of non-negative terms; a
  // negative bin made the IR synthesiser's square roots NaN).
  const double period = 1.0 / 15;
  DiffusePathCache cache(DpcWeighting::kWindow, 2 * period, period);
  for (int f = 0; f < 6; ++f) {
    PathHit h = hit(42, 1.f, 10.f);
    h.intensity[7] = f == 0 ? 1.f : f == 1 ? 1e-8f : 0.f;
    const EnergyResponse e = frame(cache, {h}, 1);
    INFO("frame " << f);
    REQUIRE(cache.entryCount() == 1);
    float lowest = 0.f;
    for (size_t k = 0; k < e.binCount(); ++k) lowest = std::min(lowest, e.bins()[k].min());
    CHECK(lowest >= 0.f);
  }
}

TEST_CASE("Window DPC: the mean over the window's frames, while its ring of terms widens, wraps "
          "and its tables grow", "[dpc]") {
  // Frames of 200-2,500 paths drawn from 6,000, so the window's terms (up to ~12,000) outgrow
  // the ring's first length, its widenings (taken with the ring wrapped at varying heads) and
  // the tables' first capacity. The oracle: per path, its intensities summed over the last W
  // frames, divided by W (fewer at the start), at its delay. Each path keeps one length, at a
  // bin's centre, so the mean delay is exact in any order of summation; the sums differ from
  // the cache's by float rounding only (relative 1e-5 of the total).
  const double period = 0.1, tau = 0.5;
  const uint64_t window = 5;
  DiffusePathCache cache(DpcWeighting::kWindow, tau, period, 64u << 20);
  Rng rng(23, 3);
  std::vector<std::vector<std::pair<uint64_t, float>>> frames;
  auto lengthOf = [](uint64_t key) { return kC * (1e-3f * float(key % 900) + 0.5e-3f); };
  for (uint64_t f = 0; f < 40; ++f) {
    std::vector<PathHit> hits;
    frames.emplace_back();
    const uint32_t count = 200 + rng.nextU32() % 2300;
    for (uint32_t i = 0; i < count; ++i) {
      const uint64_t key = rng.nextU32() % 6000;
      const float intensity = 1.f + float(key % 13);
      hits.push_back(hit(key, intensity, lengthOf(key)));
      frames.back().push_back({key, intensity});
    }
    const EnergyResponse got = frame(cache, hits, 100);
    std::vector<double> ref(got.binCount(), 0.0);
    const uint64_t first = f + 1 > window ? f + 1 - window : 0;
    const double frameCount = double(f + 1 - first);
    for (uint64_t g = first; g <= f; ++g)
      for (const auto& [key, intensity] : frames[g])
        ref[size_t(lengthOf(key) / kC / 1e-3f)] += intensity / 100.0 / frameCount;
    double total = 0.0, worst = 0.0;
    for (size_t k = 0; k < ref.size(); ++k) {
      total += ref[k];
      worst = std::max(worst, std::abs(double(got.bins()[k][0]) - ref[k]));
    }
    INFO("frame " << f << ": worst bin difference " << worst << " of total " << total);
    REQUIRE(worst <= 1e-5 * total);
  }
  CHECK(cache.mergedEntries() == 0);
}

// docs/estimators.md, "Its bias": a path hit with probability p per frame contributes I / N per hit
// in expectation. The EMA estimator's long-run mean must equal p I / N (unbiased) within Monte
// Carlo error; the thesis estimator inflates rare paths towards the harmonic number H_K.
TEST_CASE("EMA weighting is unbiased for rarely hit paths, seed weighting is not", "[dpc][heavy]") {
  const double period = 1.0 / 15, tau = 1.0;
  const uint64_t N = 1000;
  const float I = 1.f;
  for (double p : {0.02, 0.3}) {
    DiffusePathCache ema(DpcWeighting::kEma, tau, period);
    DiffusePathCache seed(DpcWeighting::kSeed, tau, period);
    Rng rng(99, uint64_t(p * 1000));
    double sumEma = 0, sumSeed = 0;
    const int frames = 60000, warmup = 200;
    for (int f = 0; f < frames; ++f) {
      std::vector<PathHit> hits;
      if (rng.uniform() < p) hits.push_back(hit(1, I, 34.3f));
      const double e = frame(ema, hits, N).total()[0];
      const double s = frame(seed, hits, N).total()[0];
      if (f >= warmup) sumEma += e, sumSeed += s;
    }
    const double truth = p * I / N;
    const double meanEma = sumEma / (frames - warmup);
    const double meanSeed = sumSeed / (frames - warmup);
    // Error of the mean: the per-frame estimate has standard deviation sqrt(p(1-p)) I / N; the
    // EMA correlates ~2/a frames, so the mean over F frames has relative standard error about
    // sqrt((1-p) / (p F a / 2)) = 4.6 % for p = 0.02. Tolerance: 4 sigma.
    const double a = 1.0 - std::exp(-period / tau);
    const double relSigma = std::sqrt((1 - p) / (p * (frames - warmup) * a / 2));
    INFO("p = " << p << " EMA mean / truth = " << meanEma / truth
                << ", seed mean / truth = " << meanSeed / truth);
    CHECK(std::abs(meanEma / truth - 1.0) < 4 * relSigma);
    if (p < 0.05) CHECK(meanSeed / truth > 2.0);  // H_15 = 3.3 for isolated hits
  }
}

// A budget small enough that the hand-built stream overflows the path table: the oldest entries
// are merged into the coarse store, later re-hit (a new path entry next to the merged state) and
// merged again. Every weighting's readout is linear in the merged state, so the response's total
// energy equals the unbounded cache's within float rounding: the energy response accumulates
// in float bins, up to ~800 terms into one bin here, worst case n * epsilon = 800 * 1.2e-7 =
// 1e-4 relative. The seed (thesis) weighting
// is linear only for paths not hit again after their merge: a re-hit starts a new entry whose
// mu counts from the re-hit, not from the path's creation (the same as the thesis's removal
// after tau), so its stream has no re-hits.
TEST_CASE("A tiny budget merges entries into the coarse store, losing no energy", "[dpc]") {
  for (DpcWeighting w : {DpcWeighting::kSeed, DpcWeighting::kEma, DpcWeighting::kWindow}) {
    INFO("weighting " << int(w));
    const double tau = 1.0, period = 0.1;
    // The smallest budget whose path table holds at least 60 entries.
    size_t budget = 4096;
    while (DiffusePathCache::capacityFor(w, tau, period, budget).entries < 60) budget += 1024;
    DiffusePathCache cache(w, tau, period, budget);
    DiffusePathCache unbounded(w, tau, period, 64u << 20);
    REQUIRE(cache.bytes() <= budget);
    REQUIRE(cache.maxEntries() < 120);
    Rng rng(17, uint64_t(w));
    for (uint64_t f = 0; f < 40; ++f) {
      // 40 new paths a frame plus re-hits of paths up to 12 frames old (merged by then), some
      // at delays beyond the coarse store's first range so that its bins widen.
      std::vector<PathHit> hits;
      for (uint64_t i = 0; i < 40; ++i)
        hits.push_back(hit(f * 1000 + i, 1.f + float(i % 7), 10.f + float(i % 5) * 40.f));
      for (int k = 0; k < (w == DpcWeighting::kSeed ? 0 : 30); ++k) {
        const uint64_t g = f - std::min<uint64_t>(f, rng.nextU32() % 12), i = rng.nextU32() % 40;
        hits.push_back(hit(g * 1000 + i, 1.f + float(i % 7), 10.f + float(i % 5) * 40.f));
      }
      if (f % 10 == 9) hits.push_back(hit(999999, 2.f, 343.f * 0.9f));
      const EnergyResponse capped = frame(cache, hits, 100);
      const EnergyResponse ref = frame(unbounded, hits, 100);
      REQUIRE(cache.entryCount() <= cache.maxEntries());
      REQUIRE(cache.bytesInUse() <= cache.bytes());
      const double a = capped.total()[0], b = ref.total()[0];
      INFO("frame " << f << " capped " << a << " unbounded " << b);
      REQUIRE(std::abs(a - b) <= 1e-4 * b);
    }
    CHECK(unbounded.mergedEntries() == 0);
    CHECK(cache.mergedEntries() >= 500);
    CHECK(cache.coarseEntryCount() > 0);
    CHECK(cache.coarseEnergyFraction() > 0.2);
    CHECK(cache.coarseEnergyFraction() < 1.0);
    // The path table keeps the most recently hit (or created) paths.
    CHECK(cache.oldestEntryFrame() + 12 >= 39);
  }
}

TEST_CASE("A budget too small for one entry is a one-line error naming the field", "[dpc]") {
  try {
    DiffusePathCache cache(DpcWeighting::kWindow, 1.0, 1.0 / 15, 2000);
    FAIL("no error");
  } catch (const std::invalid_argument& e) {
    CHECK(std::string(e.what()).find("cache_memory_mb") == 0);
  }
}
