// The headless noise comparison: static source and listener in a
// shoebox, equal rays per frame; DPC against plain path tracing, both against a converged
// plain path-tracing reference, in 10 ms bins of the band energy response.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>

#include "bench/noise_study.h"
#include "engine/path_cache.h"
#include "engine/simulation.h"
#include "testing/test_scenes.h"

using namespace dpc;

TEST_CASE("DPC halves the noise and flicker of plain path tracing at equal rays",
          "[noise][statistics]") {
  // Scattering 0.7: mostly diffuse, the case the DPC is for; absorption as a furnished room.
  const glm::vec3 size(10, 3, 7), source(2.5f, 1.5f, 2.f), listener(7.f, 1.6f, 4.5f);
  SceneDesc scene = test::makeShoebox(size, Bands(0.15f), 0.7f, source, listener, 0.5f);
  PropagationSettings ps;
  ps.raysPerFrame = 2000;
  ps.maxOrder = 60;
  ps.frameRate = 15.f;
  ps.cacheTau = 1.0f;
  ps.irLength = 1.0f;
  ps.patchSize = 0.5f;
  ps.seed = 2026;

  double refError = 0.0;
  PropagationSettings refSettings = ps;
  refSettings.seed = 777;  // independent of the runs under test
  const int refFrames = 300;
  const EnergyResponse reference =
      referenceResponse(scene, refSettings, listener, refFrames, &refError);
  auto at = [&](int) { return listener; };
  auto ref = [&](int) -> const EnergyResponse& { return reference; };

  const int warmup = 30, frames = 60;  // warm-up: 2 tau
  PropagationSettings pt = ps, ema = ps, seed = ps;
  pt.estimator = Estimator::kPathTracing;
  ema.estimator = seed.estimator = Estimator::kDpc;
  ema.dpcWeighting = DpcWeighting::kEma;
  seed.dpcWeighting = DpcWeighting::kSeed;
  const NoiseMetrics mPt = measureNoise(scene, pt, warmup, frames, at, ref);
  const NoiseMetrics mEma = measureNoise(scene, ema, warmup, frames, at, ref);
  const NoiseMetrics mSeed = measureNoise(scene, seed, warmup, frames, at, ref);

  std::printf(
      "noise study (%d rays/frame, tau %.1f s, %d frames after %d warm-up; reference %d frames, "
      "own error %.4f)\n",
      ps.raysPerFrame, ps.cacheTau, frames, warmup, refFrames, refError);
  for (auto [name, m] : {std::pair{"path_tracing", &mPt}, std::pair{"dpc_ema", &mEma},
                         std::pair{"dpc_seed", &mSeed}})
    std::printf("  %-13s error %.4f  flicker %.4f  bias %.4f  energy bias %+.4f\n", name,
                m->meanError, m->meanFlicker, m->bias, m->energyBias);

  // The required ratios: error and flicker of the default DPC at most 0.5 x PT.
  CHECK(mEma.meanError <= 0.5 * mPt.meanError);
  CHECK(mEma.meanFlicker <= 0.5 * mPt.meanFlicker);
  // Bias bound for the unbiased (EMA) estimator: what remains of the mean over F frames is
  // noise, about error / sqrt(F_eff) with F_eff = F a / 2 ~ F / (2 K) effective independent
  // frames (K = tau * frame rate = 15), plus the reference's own error, plus 2 % for the
  // delay averaging within a path group (arrivals of one group land at the group's mean
  // delay; with lambda = 0.5 m the spread is well under one 10 ms bin but moves energy across
  // bin edges). Bound: 3 x noise + reference error + 0.02.
  const double effFrames = frames * (1.0 - std::exp(-1.0 / (ps.frameRate * ps.cacheTau))) / 2.0;
  const double emaBound = 3.0 * mEma.meanError / std::sqrt(effFrames) + refError + 0.02;
  INFO("EMA bias bound " << emaBound);
  CHECK(mEma.bias <= emaBound);
  CHECK(std::abs(mEma.energyBias) <= emaBound);
  // Plain path tracing is unbiased: its mean over frames has error ~ error / sqrt(F).
  CHECK(mPt.bias <= 3.0 * mPt.meanError / std::sqrt(double(frames)) + refError + 0.01);
}

TEST_CASE("DPC total energy is path tracing's on the same rays, averaged as the cache averages",
          "[noise][statistics]") {
  // The same seed traces the same rays in every frame, so the cache's readout must carry
  // exactly path tracing's energy: for the window the mean of the last W = tau * frame rate
  // frames, for the EMA the exponential average read out divided by 1 - (1 - a)^f. Any
  // estimator bias (energy lost when entries are merged or retired, double counting, wrong
  // normalisation by the rays) would show here far above float rounding. Run at the default
  // budget and at 1 MB, where the cache merges entries into its coarse store.
  const glm::vec3 size(10, 3, 7), source(2.5f, 1.5f, 2.f), listener(7.f, 1.6f, 4.5f);
  const SceneDesc scene = test::makeShoebox(size, Bands(0.1f), 1.0f, source, listener, 0.5f);
  for (const double budgetMb : {64.0, 1.0}) {
    PropagationSettings ps;
    ps.raysPerFrame = 4000;
    ps.maxOrder = 100;
    ps.frameRate = 15.f;
    ps.cacheTau = 0.5f;  // W = 7.5 -> 8 frames
    ps.irLength = 1.0f;
    ps.seed = 99;
    ps.cacheMemoryMb = float(budgetMb);
    auto at = [&](int) { return listener; };
    const EnergyResponse any = referenceResponse(scene, ps, listener, 1, nullptr);
    auto ref = [&](int) -> const EnergyResponse& { return any; };  // errors are not used
    const int frames = 24;
    PropagationSettings pt = ps, window = ps, ema = ps;
    pt.estimator = Estimator::kPathTracing;
    window.estimator = ema.estimator = Estimator::kDpc;
    window.dpcWeighting = DpcWeighting::kWindow;
    ema.dpcWeighting = DpcWeighting::kEma;
    const std::vector<double> ePt = measureNoise(scene, pt, 0, frames, at, ref).energyPerFrame;
    const std::vector<double> eWin = measureNoise(scene, window, 0, frames, at, ref).energyPerFrame;
    const std::vector<double> eEma = measureNoise(scene, ema, 0, frames, at, ref).energyPerFrame;
    const std::vector<double> wantWin =
        cacheAveraged(ePt, DpcWeighting::kWindow, ps.cacheTau, ps.frameRate);
    const std::vector<double> wantEma =
        cacheAveraged(ePt, DpcWeighting::kEma, ps.cacheTau, ps.frameRate);
    double worstWin = 0.0, worstEma = 0.0;
    for (int f = 0; f < frames; ++f) {
      worstWin = std::max(worstWin, std::abs(eWin[size_t(f)] / wantWin[size_t(f)] - 1.0));
      worstEma = std::max(worstEma, std::abs(eEma[size_t(f)] / wantEma[size_t(f)] - 1.0));
    }
    std::printf(
        "budget %.0f MB: total energy vs path tracing of the same rays, worst frame: "
        "window %.2e, EMA %.2e\n",
        budgetMb, worstWin, worstEma);
    // Float sums over ~1e5 contributions: 1e-5. The EMA also drops an entry once its weight is
    // below kEmaDropFraction (1e-4 of a hit's): at most that share of the energy.
    CHECK(worstWin < 1e-5);
    CHECK(worstEma < 1e-5 + DiffusePathCache::kEmaDropFraction);
    if (budgetMb == 1.0) {  // the budget case does merge
      Simulation sim(scene, window);
      for (int f = 0; f < frames; ++f) sim.runFrame(listener);
      CHECK(sim.result(0).cacheMergedEntries > 0);
    }
  }
}
