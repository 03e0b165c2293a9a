// Sources' own IRs kept across frames (PropagationStage::reuseSourceIrs: whole IRs, or the
// early parts of hybrid rendering): a source keeps the IR it plays while its exact arrivals and
// its diffuse energy match what that IR was made from (EarlySignature), and synthesises it
// again as soon as it moves. Oracles: arrivals and responses the test builds itself; in the stage, the direct
// sound's delay from the positions (distance / c), and the IRs of a stage that synthesises
// every early part every frame from the same responses (same seed, bit-identical estimates).
#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "runtime/early_signature.h"
#include "runtime/ir_exchange.h"
#include "runtime/live_session.h"
#include "runtime/propagation_stage.h"
#include "scene/trajectory.h"
#include "tests/runtime/same_partitions.h"
#include "testing/test_scenes.h"

using namespace dpc;

namespace {

/// A 0.2 s early response: a decay from 5 ms on times independent Gamma noise of mean 1 and
/// relative variance 1 / kappa per 1 ms bin (a Monte Carlo estimate's scatter).
EnergyResponse earlyResponse(std::mt19937& rng, double kappa, float scale = 1.f) {
  std::gamma_distribution<double> g(kappa, 1.0 / kappa);
  EnergyResponse r(0.2, 0.001);
  for (size_t j = 5; j < r.binCount(); ++j)
    for (int b = 0; b < kNumBands; ++b)
      r.bins()[j][b] = scale * float(1e-3 * std::exp(-double(j) * 0.001 / 0.1) * g(rng));
  return r;
}

DirectSound direct() {
  DirectSound d;
  d.visible = true;
  d.distance = 3.43f;
  d.delaySeconds = 0.01f;
  d.intensity = Bands(0.1f);
  d.direction = {1.f, 0.f, 0.f};
  return d;
}

std::vector<SpecularPath> paths() {
  std::vector<SpecularPath> p(3);
  for (size_t i = 0; i < p.size(); ++i) {
    p[i].key = 11 * (i + 1);
    p[i].order = 1;
    p[i].delaySeconds = 0.02 + 0.01 * double(i);
    p[i].intensity = Bands(0.01f);
    p[i].direction = glm::normalize(glm::vec3(float(i), 1.f, 0.5f));
  }
  return p;
}

bool matches(const EnergyResponse& r, const DirectSound& d, const std::vector<SpecularPath>& p,
             const EarlySignature& made) {
  EarlySignature now;
  now.assign(r, d, p);
  return now.matches(made, 0.5);
}

}  // namespace

TEST_CASE("Early signature: the same arrivals match, any audible change does not", "[hybrid]") {
  std::mt19937 rng(3);
  const EnergyResponse r = earlyResponse(rng, 400.0);
  EarlySignature made;
  made.assign(r, direct(), paths());
  std::vector<SpecularPath> p = paths();
  std::reverse(p.begin(), p.end());
  CHECK(matches(r, direct(), p, made));  // the order of discovery does not matter
  DirectSound d = direct();
  d.delaySeconds += 1.f / 48000.f;  // one sample later
  CHECK_FALSE(matches(r, d, paths(), made));
  d = direct();
  d.delaySeconds += 2e-6f;  // 0.7 mm: below a quarter sample
  CHECK(matches(r, d, paths(), made));
  p = paths();
  p[1].intensity[3] *= 1.3f;  // +1.1 dB in one band
  CHECK_FALSE(matches(r, direct(), p, made));
  p = paths();
  p[1].intensity[3] *= 1.1f;  // +0.4 dB: within 0.5 dB
  CHECK(matches(r, direct(), p, made));
  p = paths();
  p.pop_back();
  CHECK_FALSE(matches(r, direct(), p, made));
  p = paths();
  p[2].key = 99;  // another path at the same delay
  CHECK_FALSE(matches(r, direct(), p, made));
  d = direct();
  d.visible = false;
  CHECK_FALSE(matches(r, d, paths(), made));
  // The diffuse part 3 dB louder, in estimates far quieter than that.
  EnergyResponse louder = earlyResponse(rng, 400.0, 2.f);
  CHECK_FALSE(matches(louder, direct(), paths(), made));
}

TEST_CASE("Early signature: the cells are compared as they are, without a noise margin",
          "[hybrid]") {
  // An early part's bins hold discrete reflections: the scatter between neighbouring bins is
  // structure, not only noise, so a margin read from it (LateShape's) would let real changes
  // through. Two estimates whose 1 ms bins scatter by 5 % (kappa 400; their 50 ms cells by
  // 0.03 dB) match; with 50 % (kappa 4; the cells after 50 ms, where the diffuse part carries
  // the energy, 0.3 dB each) the largest cell differs by more than 0.5 dB in most pairs, and the
  // IR is synthesised anew.
  std::mt19937 rng(11);
  int quietMismatched = 0, noisyMismatched = 0;
  const int trials = 200;
  for (int i = 0; i < trials; ++i) {
    EarlySignature quiet, noisy;
    quiet.assign(earlyResponse(rng, 400.0), direct(), paths());
    noisy.assign(earlyResponse(rng, 4.0), direct(), paths());
    quietMismatched += !matches(earlyResponse(rng, 400.0), direct(), paths(), quiet);
    noisyMismatched += !matches(earlyResponse(rng, 4.0), direct(), paths(), noisy);
  }
  CHECK(quietMismatched == 0);
  CHECK(noisyMismatched > trials / 2);
}

TEST_CASE("Early signature: spatial output sees a turned head and a moved arrival", "[hybrid]") {
  const std::vector<glm::vec3> dirs = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0},
                                       {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  DirectionalEnergyResponse r(0.2, 0.001, dirs);
  r.setListenerFrame({1, 0, 0}, {0, 1, 0});
  for (int j = 0; j < 150; ++j)
    r.add(0.012 + 0.001 * j, Bands(1e-4f * std::exp(-0.03f * float(j))),
          glm::normalize(glm::vec3(std::cos(j), 0.3f, std::sin(j))));
  EarlySignature made, now;
  made.assign(r, direct(), paths());
  now.assign(r, direct(), paths());
  CHECK(now.matches(made, 0.5));
  const auto turned = [](float degrees) {
    const float a = degrees * float(M_PI) / 180.f;
    return glm::vec3(std::cos(a), 0.f, std::sin(a));
  };
  DirectionalEnergyResponse head = r;
  head.setListenerFrame(turned(2.f), {0, 1, 0});  // the head turned by 2 degrees
  now.assign(head, direct(), paths());
  CHECK_FALSE(now.matches(made, 0.5));
  DirectSound d = direct();
  d.direction = turned(2.f);
  now.assign(r, d, paths());
  CHECK_FALSE(now.matches(made, 0.5));
  d.direction = turned(0.5f);  // within the minimum audible angle
  now.assign(r, d, paths());
  CHECK(now.matches(made, 0.5));
}

namespace {

/// Energy of an IR's first n samples over its channels.
double energyTo(const ImpulseResponse& ir, size_t n) {
  double e = 0.0;
  for (int c = 0; c < ir.channels(); ++c)
    for (size_t i = 0; i < std::min(n, ir.samples()); ++i)
      e += double(ir.channel(c)[i]) * double(ir.channel(c)[i]);
  return e;
}

/// The sample where an IR's channels together peak.
size_t peakSample(const ImpulseResponse& ir) {
  size_t best = 0;
  double most = -1.0;
  for (size_t i = 0; i < ir.samples(); ++i) {
    double e = 0.0;
    for (int c = 0; c < ir.channels(); ++c) e += double(ir.channel(c)[i]) * ir.channel(c)[i];
    if (e > most) most = e, best = i;
  }
  return best;
}

/// test::ringScene's sources and listener, rendered hybrid (9 sources, 2 buses) or each
/// source whole (3 sources).
struct RingStage {
  SceneDesc scene;
  std::unique_ptr<PropagationStage> stage;
  WorldState world;
  RingStage(double toleranceDb, Rendering rendering = Rendering::kHybrid)
      : scene(test::ringScene(rendering == Rendering::kHybrid ? 9 : 3)) {
    scene.audio.rendering = rendering;
    scene.audio.lateBuses = 2;
    stage = std::make_unique<PropagationStage>(test::shared(scene), scene.propagation);
    stage->reuseSourceIrs(toleranceDb);
    evaluateWorld(scene, 0.0, world);
  }
  size_t sources() const { return scene.sources.size(); }
  void frame() {
    stage->traceWorld(world);
    stage->synthesizeIrs(0);
  }
};

}  // namespace

TEST_CASE("Source IRs kept: a still source keeps its IR, a moved one is heard where it is",
          "[hybrid][heavy]") {
  for (const Rendering rendering : {Rendering::kHybrid, Rendering::kPerSource}) {
    INFO("rendering " << int(rendering));
    RingStage kept(0.5, rendering), fresh(0.0, rendering);
    REQUIRE((kept.stage->hybrid() != nullptr) == (rendering == Rendering::kHybrid));
    const size_t S = kept.sources();
    for (int f = 0; f < 12; ++f) {
      kept.frame();
      fresh.frame();
    }
    // Kept from the third frame (the first two make the IR with, then without, what changed);
    // more than half of frames 3-12's IRs while the young caches still move.
    CHECK(kept.stage->sourceIrCounts(0).kept > 5 * S);
    CHECK(kept.stage->sourceIrCounts(0).kept + kept.stage->sourceIrCounts(0).synthesized ==
          12 * S);
    CHECK(fresh.stage->sourceIrCounts(0).kept == 0);
    // A kept IR against this frame's own synthesis: the same exact arrivals, and a diffuse
    // part within 0.5 dB beyond its Monte Carlo margin; the direct sound and the exact paths
    // carry most of the early energy, so 1 dB bounds the difference.
    const size_t early = kept.stage->hybrid() ? kept.stage->hybrid()->earlySamples()
                                              : size_t(0.08 * kept.scene.audio.sampleRate);
    for (size_t s = 0; s < S; ++s) {
      INFO("source " << s);
      const double a = energyTo(kept.stage->lastIrs(0)[s], early);
      const double b = energyTo(fresh.stage->lastIrs(0)[s], early);
      CHECK(std::abs(10.0 * std::log10(a / b)) < 1.0);
    }
    // Source 1 steps 0.6 m toward the listener: synthesised again, its direct sound at the new
    // delay (distance / c, within the band filters' spread of 2 samples).
    const uint64_t before = kept.stage->sourceIrId(0, 1);
    const glm::vec3 listener = kept.world.listenerPositions[0];
    glm::vec3& p = kept.world.sourcePositions[1];
    p += 0.6f * glm::normalize(listener - p);
    kept.frame();
    CHECK(kept.stage->sourceIrId(0, 1) != before);
    const double fs = kept.scene.audio.sampleRate;
    const double delay = glm::length(listener - p) / kept.scene.propagation.speedOfSound;
    CHECK(std::abs(double(peakSample(kept.stage->lastIrs(0)[1])) - delay * fs) <= 2.0);
  }
}

TEST_CASE("A kept early IR is partitioned once per set: a recycled set holds what a new one would",
          "[hybrid]") {
  RingStage ring(6.0);  // kept from the second frame on
  PropagationStage& stage = *ring.stage;
  const auto exchange = stage.makeExchange(1, 3);
  IrSet *a = exchange->acquire(), *b = exchange->acquire(), *fresh = exchange->acquire();
  REQUIRE((a && b && fresh));
  // Past the first frames, while the exact paths are still being found.
  for (int f = 0; f < 8; ++f) ring.frame();
  stage.traceWorld(ring.world);
  stage.prepare(0, *a);
  stage.traceWorld(ring.world);
  stage.prepare(0, *b);
  const uint64_t id = stage.sourceIrId(0, 0);
  REQUIRE(id != 0);
  stage.traceWorld(ring.world);
  stage.prepare(0, *a);  // kept since a was filled: a keeps its partitions
  REQUIRE(stage.sourceIrId(0, 0) == id);
  stage.prepare(0, *fresh);  // the same frame into a set that never held it
  CHECK(fresh->irIds[0] == id);
  CHECK(test::samePartitions(*a->irs, *fresh->irs, 0));
  // Source 0 moves: a set that held its old IR takes the new one.
  ring.world.sourcePositions[0] += glm::vec3(0.5f, 0.f, 0.f);
  stage.traceWorld(ring.world);
  stage.prepare(0, *b);
  CHECK(stage.sourceIrId(0, 0) != id);
  CHECK(b->irIds[0] == stage.sourceIrId(0, 0));
  CHECK_FALSE(test::samePartitions(*a->irs, *b->irs, 0));
}

TEST_CASE("A live session keeps still sources' IRs by default, and 0 dB turns it off",
          "[hybrid][live]") {
  SceneDesc scene = test::ringScene(6);
  scene.audio.rendering = Rendering::kHybrid;
  scene.audio.lateBuses = 2;
  const auto dry = test::shared(loadDrySignals(scene));
  const auto run = [&](LiveSession::Options o) {
    LiveSession session(test::shared(scene), scene.propagation, dry, o);
    for (int f = 0; f < 8; ++f) REQUIRE(session.step());
    return session.sourceIrCounts();
  };
  const KeptIrs::Counts on = run({}), off = run([] {
    LiveSession::Options o;
    o.sourceIrToleranceDb = 0.0;
    return o;
  }());
  CHECK(on.kept > 0);
  CHECK(off.kept == 0);
  CHECK(off.synthesized == 8 * 6);
  LiveSession::Options bad;
  bad.sourceIrToleranceDb = 7.0;
  CHECK_THROWS_AS(LiveSession(test::shared(scene), scene.propagation, dry, bad),
                  std::invalid_argument);
}

namespace {

/// The plugin's default room (plugins/lv2/scene/room.json): a 10 x 7 x 3 m box, the source at
/// x = 3, a listener facing it from x = 7, stereo.
SceneDesc pluginRoom() {
  SceneDesc scene = test::makeShoebox({10, 3, 7}, Bands(0.1f), 0.2f, {3, 1.6f, 3.5f},
                                      {7, 1.6f, 3.5f});
  scene.audio.output = OutputFormat::kStereo;
  scene.audio.blockSize = 256;
  scene.propagation.raysPerFrame = 2048;
  scene.propagation.irLength = 1.5f;
  return scene;
}

/// Energy of a session's output within +-w samples of `at` after an impulse at its input,
/// after 20 frames at x = 7, a move to x = 9 and 20 frames there.
double directAfterMove(double toleranceDb, size_t at, size_t w) {
  const SceneDesc scene = pluginRoom();
  LiveSession::Options o;
  o.sourceIrToleranceDb = toleranceDb;
  LiveSession session(test::shared(scene), scene.propagation,
                      test::shared(loadDrySignals(scene)), o);
  const int block = 256;
  std::vector<float> in(block, 0.f), left(block), right(block);
  const float* inputs[] = {in.data()};
  float* outputs[] = {left.data(), right.data()};
  for (int f = 0; f < 40; ++f) {
    if (f == 20) REQUIRE(session.setListenerPose(0, {9.f, 1.6f, 3.5f}, float(M_PI), 0.0));
    REQUIRE(session.step());
    session.render(inputs, outputs, block);  // takes the newest set
  }
  for (int b = 0; b < 200; ++b) session.render(inputs, outputs, block);  // crossfades done
  std::vector<float> out;
  for (int b = 0; b < 20; ++b) {
    in[0] = b == 0 ? 1.f : 0.f;
    session.render(inputs, outputs, block);
    for (int i = 0; i < block; ++i) out.push_back(left[size_t(i)] * left[size_t(i)] +
                                                  right[size_t(i)] * right[size_t(i)]);
  }
  double e = 0.0;
  for (size_t i = at - w; i <= at + w; ++i) e += out[i];
  return e;
}

}  // namespace

TEST_CASE("Source IRs kept: a listener that moved is heard at its new place",
          "[hybrid][live][heavy]") {
  const SceneDesc scene = pluginRoom();
  const double fs = scene.audio.sampleRate, c = scene.propagation.speedOfSound;
  LiveSession probe(test::shared(scene), scene.propagation, test::shared(loadDrySignals(scene)),
                    {});
  const size_t at = size_t(probe.adapterLatencyFrames()) + size_t(std::lround(6.0 / c * fs));
  const double kept = directAfterMove(0.5, at, 12), fresh = directAfterMove(0.0, at, 12);
  INFO("kept " << kept << " fresh " << fresh);
  REQUIRE(fresh > 0.0);
  CHECK(std::abs(10.0 * std::log10(kept / fresh)) < 0.5);
}
