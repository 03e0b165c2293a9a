// Hybrid rendering's late buses kept across frames (HybridSynthesis::reuseLateBuses): a bus
// keeps the IR it plays while its decay's shape holds, and each source is still heard with
// exactly its own late energy, even when that energy jumps while the bus's IR stays. The
// oracle is the response the session itself reports for the same frame (copyResponses: the
// energy response and the IR as the audio thread plays it), read with the test's own sums.
#include <catch2/catch.hpp>
#include <cmath>
#include <algorithm>
#include <memory>
#include <random>
#include <string>

#include "runtime/late_shape.h"
#include "runtime/ir_exchange.h"
#include "runtime/live_session.h"
#include "runtime/propagation_stage.h"
#include "scene/trajectory.h"
#include "scene/scene.h"
#include "tests/runtime/same_partitions.h"
#include "testing/test_scenes.h"

using namespace dpc;

TEST_CASE("Late shape: blind to the level, sees a band's decay change", "[hybrid]") {
  EnergyResponse r(1.0, 0.001);
  for (size_t j = 0; j < r.binCount(); ++j)
    for (int b = 0; b < kNumBands; ++b)
      r.bins()[j][b] = float(std::exp(-double(j) * 0.001 / (0.05 + 0.02 * b)));
  const double start = 0.1;
  EnergyResponse louder = r;
  for (Bands& bin : louder.bins()) bin = bin * 4.f;
  const LateShape a = LateShape::of(r, start);
  CHECK(a.maxDifferenceDb(LateShape::of(louder, start)) < 1e-6);
  CHECK(LateShape::of(louder, start).total() == Approx(4.0 * a.total()).epsilon(1e-6));
  // 1 kHz (band 4) 2 dB stronger from 300 ms on: its cells from 200 ms after the start differ
  // by 2 dB less the total's share of the change (the shape is relative to the total).
  EnergyResponse tilted = r;
  double added = 0.0, total = 0.0;
  for (size_t j = 0; j < r.binCount(); ++j) {
    const double t = (double(j) + 0.5) * r.binSeconds();
    for (int b = 0; b < kNumBands; ++b)
      if (t >= start) total += r.bins()[j][b];
    if (t < 0.3) continue;
    const float before = tilted.bins()[j][4];
    tilted.bins()[j][4] = before * float(std::pow(10.0, 0.2));
    added += double(tilted.bins()[j][4] - before);
  }
  const double expected = 2.0 - 10.0 * std::log10((total + added) / total);
  CHECK(a.maxDifferenceDb(LateShape::of(tilted, start)) == Approx(expected).margin(0.01));
  CHECK(std::isinf(a.maxDifferenceDb(LateShape::of(EnergyResponse(1.0, 0.001), start))));
}

namespace {

/// Source s's played IR energy from `from` seconds on (sum of squares over its channels) and
/// its energy response's, bands summed, as the session reports them for its last frame.
struct LateEnergy {
  double ir = 0.0, response = 0.0;
};
LateEnergy lateEnergy(LiveSession& session, size_t s, double from) {
  LateEnergy e;
  REQUIRE(session.copyResponses(s, [&](const LiveSession::Responses& r) {
    const size_t first = size_t(std::ceil(from * r.ir->sampleRate()));
    for (int c = 0; c < r.ir->channels(); ++c)
      for (size_t i = first; i < r.ir->samples(); ++i)
        e.ir += double(r.ir->channel(c)[i]) * double(r.ir->channel(c)[i]);
    for (size_t j = size_t(std::ceil(from / r.binSeconds)); j < r.energy->size(); ++j)
      e.response += double((*r.energy)[j].sum());
  }));
  REQUIRE(e.ir > 0.0);
  return e;
}

/// A session on two_rooms rendering hybrid with both sources on one late bus, its buses kept
/// within toleranceDb (0: every bus synthesised every frame).
std::unique_ptr<LiveSession> twoRoomsSession(double toleranceDb) {
  SceneDesc scene = loadScene(std::string(DPC_SOURCE_DIR) + "/scenes/two_rooms.json");
  scene.audio.rendering = Rendering::kHybrid;
  scene.audio.lateBuses = 1;
  PropagationSettings ps = scene.propagation;
  ps.raysPerFrame = 4096;
  LiveSession::Options o;
  o.lateBusToleranceDb = toleranceDb;
  return std::make_unique<LiveSession>(test::shared(scene), ps,
                                       test::shared(loadDrySignals(scene)), o);
}

/// Four frames, then the second source (in the far room, heard through the doorway) jumps
/// into the listener's room, then four frames more: its late energy rises by many dB; the
/// bus's decay shape much less.
void jumpSecondSource(LiveSession& session) {
  for (int f = 0; f < 4; ++f) REQUIRE(session.step());
  REQUIRE(session.setSourcePosition(1, glm::vec3(4.5f, 1.6f, 3.0f)));
  REQUIRE(session.teleportSource(1));
  for (int f = 0; f < 4; ++f) REQUIRE(session.step());
}

}  // namespace

TEST_CASE("Late buses kept: each source keeps its own late level when it jumps", "[hybrid]") {
  // The same frames twice (same seed, same inputs: bit-identical responses), once with the
  // bus kept through the jump and once synthesised every frame, the reference.
  const auto kept = twoRoomsSession(6.0), fresh = twoRoomsSession(0.0);
  jumpSecondSource(*kept);
  jumpSecondSource(*fresh);
  const HybridReport h = kept->hybridReport();
  REQUIRE(h.on);
  CHECK(h.counts.busesKept > 0);
  CHECK(fresh->hybridReport().counts.busesKept == 0);
  // From the end of the early part on (its crossfade past), each source's played late energy
  // equals the reference's: each synthesis keeps the broadband level of its IR exact
  // (validate_ir: within 0.06 dB), and a late window of thousands of pulses scatters by about
  // 0.1 dB; 0.5 dB allows both. Gains against the bus's current energy instead of the energy
  // its kept IR was made from would miss by the bus's change, several dB here.
  const double from = h.earlySeconds + 0.02;
  for (size_t s = 0; s < 2; ++s) {
    INFO("source " << s);
    const LateEnergy a = lateEnergy(*kept, s, from), b = lateEnergy(*fresh, s, from);
    CHECK(a.response == b.response);
    CHECK(std::abs(10.0 * std::log10(a.ir / b.ir)) < 0.5);
  }
}

namespace {

/// A late response m_k (each band its own decay) times independent Gamma noise of mean 1 and
/// relative variance 1 / kappa per 1 ms bin: a Monte Carlo estimate whose bins scatter as a
/// path tracer's do.
EnergyResponse noisyDecay(std::mt19937& rng, double kappa) {
  std::gamma_distribution<double> g(kappa, 1.0 / kappa);
  EnergyResponse r(1.0, 0.001);
  for (size_t j = 0; j < r.binCount(); ++j)
    for (int b = 0; b < kNumBands; ++b)
      r.bins()[j][b] = float(std::exp(-double(j) * 0.001 / (0.25 - 0.02 * b)) * g(rng));
  return r;
}

}  // namespace

TEST_CASE("Late shape: a cell's Monte Carlo variance is read from the response itself",
          "[hybrid]") {
  // Oracle: the spread of the cells over 400 independent realisations. The estimate's mean
  // over them against it within 20 %: the empirical variance of 400 draws is itself within
  // sqrt(2 / 400) = 7 % (1 sigma), so 20 % is 3 sigma.
  std::mt19937 rng(5);
  const double start = 0.1, kappa = 4.0;
  const int n = 400;
  double estimate[kNumBands][LateShape::kSegments] = {}, sum[kNumBands][LateShape::kSegments] = {},
         sum2[kNumBands][LateShape::kSegments] = {};
  for (int i = 0; i < n; ++i) {
    const EnergyResponse r = noisyDecay(rng, kappa);
    const LateShape s = LateShape::of(r, start);
    for (int b = 0; b < kNumBands; ++b)
      for (int q = 0; q < LateShape::kSegments; ++q) {
        // The cell's energy (the shape times the total), and its estimated relative variance.
        double cell = 0.0;
        for (size_t j = 0; j < r.binCount(); ++j) {
          const double t = (double(j) + 0.5) * 0.001 - start;
          const int seg = t < 0.0 ? -1 : t < 0.05 ? 0 : t < 0.1 ? 1 : t < 0.2 ? 2 : t < 0.4 ? 3
                                                  : t < 0.8 ? 4 : 5;
          if (seg == q) cell += r.bins()[j][b];
        }
        sum[b][q] += cell;
        sum2[b][q] += cell * cell;
        estimate[b][q] += s.relativeVariance(b, q) / n;
      }
  }
  for (int b = 0; b < kNumBands; ++b)
    for (int q = 0; q < 4; ++q) {  // the segments up to 400 ms: where their cells hold energy
      const double mean = sum[b][q] / n, var = sum2[b][q] / n - mean * mean;
      INFO("band " << b << " segment " << q);
      CHECK(estimate[b][q] == Approx(var / (mean * mean)).epsilon(0.2));
    }
}

TEST_CASE("Late shape: an unchanged response's scatter is no change, a change beyond it is",
          "[hybrid]") {
  std::mt19937 rng(9);
  const double start = 0.1;
  int rawOver = 0, excessOver = 0;
  const int trials = 200;
  for (int i = 0; i < trials; ++i) {
    const LateShape a = LateShape::of(noisyDecay(rng, 4.0), start);
    const LateShape b = LateShape::of(noisyDecay(rng, 4.0), start);
    rawOver += a.maxDifferenceDb(b) > 0.5;
    excessOver += a.maxExcessDb(b) > 0.5;
  }
  // Two estimates of one response: their raw shapes differ by more than 0.5 dB nearly always
  // (the 50 ms cells of a bin noise of 50 % scatter by about 0.3 dB each), beyond the margin
  // of 3 sigma in about 10 % of the trials (48 cells); 25 % bounds that with margin.
  CHECK(rawOver > trials * 9 / 10);
  CHECK(excessOver < trials / 4);
  // A real change: 1 kHz 3 dB stronger from 300 ms on, in estimates of a tenth the scatter.
  EnergyResponse quiet = noisyDecay(rng, 400.0), changed = noisyDecay(rng, 400.0);
  for (size_t j = 300; j < changed.binCount(); ++j) changed.bins()[j][4] *= 2.f;
  CHECK(LateShape::of(quiet, start).maxExcessDb(LateShape::of(changed, start)) > 1.0);
}

TEST_CASE("A kept bus IR is partitioned once per set: a recycled set holds what a new one would",
          "[hybrid]") {
  // Oracle: a set that never held the bus (its partitions made fresh from the bus's IR), filled
  // on the same frame as a recycled set that skipped the bus because it held its IR already.
  SceneDesc scene = loadScene(std::string(DPC_SOURCE_DIR) + "/scenes/two_rooms.json");
  scene.audio.rendering = Rendering::kHybrid;
  scene.audio.lateBuses = 1;
  auto shared = test::shared(scene);
  PropagationSettings ps = scene.propagation;
  ps.raysPerFrame = 2048;
  PropagationStage stage(shared, ps);
  stage.reuseLateBuses(6.0);  // the bus is kept from the second frame on
  const auto exchange = stage.makeExchange(1, 3);
  IrSet *a = exchange->acquire(), *b = exchange->acquire(), *fresh = exchange->acquire();
  REQUIRE((a && b && fresh));
  WorldState world;
  auto frame = [&](IrSet& set) {
    evaluateWorld(scene, 0.0, world);
    stage.traceWorld(world);
    stage.prepare(0, set);
  };
  frame(*a);
  frame(*b);
  const uint64_t kept = stage.hybrid()->busIrId(0, 0);
  frame(*a);  // kept since a was filled: a keeps its partitions
  REQUIRE(stage.hybrid()->counts(0).busesKept >= 2);
  REQUIRE(stage.hybrid()->busIrId(0, 0) == kept);
  stage.prepare(0, *fresh);  // the same frame into a set that never held the bus
  CHECK(fresh->lateIrIds[0] == kept);
  CHECK(test::samePartitions(*a->lateIrs, *fresh->lateIrs, 0));
  // Remade every frame from here: a set holding the old IR must take the new one.
  stage.reuseLateBuses(0.0);
  frame(*b);
  frame(*a);
  CHECK(stage.hybrid()->busIrId(0, 0) != kept);
  CHECK(a->lateIrIds[0] == stage.hybrid()->busIrId(0, 0));
  IrSet* other = exchange->acquire();
  REQUIRE(other);
  stage.reuseLateBuses(6.0);  // keep the IR a was just filled with
  stage.prepare(0, *other);
  CHECK(test::samePartitions(*a->lateIrs, *other->lateIrs, 0));
  // b, one frame older, holds another IR.
  CHECK_FALSE(test::samePartitions(*b->lateIrs, *a->lateIrs, 0));
}
