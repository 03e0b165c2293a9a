// Hybrid rendering (runtime/hybrid_synthesis.h): each source rendered with its early part on
// its own and its late part through its cluster's shared bus must sound like the source
// rendered whole. Oracle: the same scene rendered per source (PropagationSettings and seed
// equal, so both renderings start from the same energy responses, bit for bit); each source's
// rendered IR is read through the audio stage itself, an impulse into that source alone.
#include <catch2/catch.hpp>
#include <cmath>
#include <memory>
#include <vector>

#include "runtime/audio_stage.h"
#include "runtime/propagation_stage.h"
#include "scene/trajectory.h"
#include "testing/test_scenes.h"
#include "testing/test_util.h"

using namespace dpc;
using test::ringScene;

namespace {

/// Two rooms (14 x 3 x 6 m, a wall at x = 7 with a 1 x 2 m doorway at z 5..6): room A
/// (x < 7) hard, room B's floor and ceiling absorbing the high bands (0.1 at 63 Hz rising to
/// 0.7 at 8 kHz), so sources in B reach the listener in A with another late spectrum and decay.
/// Listener at (3, 1.6, 2); three sources in A near the wall at x = 6 and three behind it in B
/// at x = 10, at the same z: seen from the listener each B source lies within 11 degrees of an
/// A source, but the wall hides them from each other.
SceneDesc coupledScene() {
  SceneDesc s = test::makeShoebox({14, 3, 6}, Bands(0.1f), 0.5f, {6, 1.2f, 1}, {3, 1.6f, 2});
  const glm::vec3 y{0, 1, 0}, z{0, 0, 1}, x{1, 0, 0};
  test::addPanel(s.mesh, {7, 0, 0}, 5.f * z, 3.f * y, 0);
  test::addPanel(s.mesh, {7, 2, 5}, 1.f * z, 1.f * y, 0);
  Bands dead;
  for (int b = 0; b < kNumBands; ++b) dead[b] = 0.1f + 0.6f * float(b) / float(kNumBands - 1);
  s.materials.push_back(Material{"dead", dead, Bands(0.5f)});
  test::addPanel(s.mesh, {7.01f, 0.01f, 0}, 6.f * z, 6.98f * x, 1);  // B's floor, facing up
  test::addPanel(s.mesh, {7.01f, 2.99f, 0}, 6.98f * x, 6.f * z, 1);  // B's ceiling, facing down
  s.audio.output = OutputFormat::kStereo;
  s.audio.blockSize = 256;
  s.propagation.irLength = 1.2f;
  s.propagation.raysPerFrame = 3000;
  s.sources.clear();
  for (float sx : {6.f, 10.f})
    for (float sz : {1.f, 2.f, 3.f}) {
      SourceDesc d;
      d.name = "s" + std::to_string(s.sources.size());
      d.position = {sx, 1.2f, sz};
      s.sources.push_back(d);
    }
  return s;
}

/// Every source's rendered IR (channels interleaved per sample: [c][n]) after `frames` frames.
struct Rendered {
  std::vector<std::vector<std::vector<float>>> ir;  ///< [source][channel][sample]
  int buses = 0;
  /// Hybrid: per source, the band energy its rendering holds in expectation (early part plus
  /// g_s^2 times its bus's late response) and the whole response's, from the energy responses.
  std::vector<Bands> expectedHybrid, expectedWhole;
  std::vector<ImpulseResponse> stageIrs;  ///< PropagationStage::wholeIrs()
};

Bands sum(const EnergyResponse& r) {
  return r.total();
}

/// The expected band energies of every source in hybrid rendering, against the whole
/// responses: what the clustering changes, without the synthesis's realisation noise.
void expectedEnergies(const PropagationStage& stage, const IrSet& set, Rendered& out) {
  const Simulation& sim = stage.simulation();
  const HybridSplit& split = stage.hybrid()->split();
  const size_t S = sim.sourceCount();
  std::vector<EnergyResponse> bus(size_t(out.buses), EnergyResponse(1.2, 1e-3));
  std::vector<Bands> early(S), late(S);
  for (size_t s = 0; s < S; ++s) {
    const Simulation::SourceResult& r = sim.result(s);
    EnergyResponse e = r.energy, own(1.2, 1e-3);
    addLate(r.energy, r.direct, sim.specularPaths(s), split, own);
    addLate(r.energy, r.direct, sim.specularPaths(s), split, bus[size_t(set.lateBus[s])]);
    keepEarly(e, split);
    // The exact arrivals that stay early; addLate put the others into `own`.
    early[s] = sum(e);
    if (r.direct.visible && split.arrivalIsEarly(r.direct.delaySeconds))
      early[s] += r.direct.intensity;
    for (const SpecularPath& p : sim.specularPaths(s))
      if (split.arrivalIsEarly(p.delaySeconds)) early[s] += p.intensity;
    late[s] = sum(own);
  }
  for (size_t s = 0; s < S; ++s) {
    const float g2 = set.lateGain[s] * set.lateGain[s];
    out.expectedHybrid.push_back(early[s] + sum(bus[size_t(set.lateBus[s])]) * g2);
    out.expectedWhole.push_back(early[s] + late[s]);
  }
}

Rendered render(SceneDesc scene, Rendering rendering, int frames) {
  scene.audio.rendering = rendering;
  auto shared = std::make_shared<const SceneDesc>(scene);
  PropagationStage stage(shared, scene.propagation);
  WorldState world;
  evaluateWorld(*shared, 0.0, world);
  for (int f = 0; f < frames; ++f) stage.traceWorld(world);
  auto dry = std::make_shared<DrySignals>();
  dry->samples.assign(scene.sources.size(), std::vector<float>(1, 0.f));
  dry->loop.assign(scene.sources.size(), false);
  const size_t S = scene.sources.size(), B = size_t(scene.audio.blockSize);
  const size_t C = size_t(stage.numOutputs());
  const size_t length = size_t(scene.propagation.irLength * float(scene.audio.sampleRate)) + 2 * B;
  Rendered out;
  out.buses = stage.lateBuses();
  std::vector<float> zeros(B, 0.f), impulse(B, 0.f), block(C * B);
  impulse[0] = 1.f;
  std::vector<const float*> in(S);
  std::vector<float*> outs(C);
  for (size_t c = 0; c < C; ++c) outs[c] = block.data() + c * B;
  const auto exchange = stage.makeExchange(1, 3);
  AudioStage audio(stage, dry, *exchange);
  IrSet* set = exchange->acquire();
  REQUIRE(set);
  stage.prepare(0, *set);
  if (stage.hybrid()) expectedEnergies(stage, *set, out);
  out.stageIrs = stage.wholeIrs(0);
  exchange->publish(0, set);
  // Silence for a whole IR length: the set applied at every partition level (each level
  // switches at its own chunk boundary, crossfading over that chunk) and the late gains' ramp
  // done, so every impulse below meets the new IRs only.
  for (size_t n = 0; n < length; n += B) {
    std::fill(in.begin(), in.end(), zeros.data());
    audio.process(outs.data(), in.data());
  }
  // One impulse per source, each followed by silence for its whole IR (the stage is linear).
  for (size_t s = 0; s < S; ++s) {
    std::vector<std::vector<float>> ir(C);
    for (size_t n = 0; n < length; n += B) {
      std::fill(in.begin(), in.end(), zeros.data());
      if (n == 0) in[s] = impulse.data();
      audio.process(outs.data(), in.data());
      for (size_t c = 0; c < C; ++c) ir[c].insert(ir[c].end(), outs[c], outs[c] + B);
    }
    out.ir.push_back(std::move(ir));
  }
  return out;
}

double energy(const std::vector<float>& x, size_t from, size_t to) {
  double e = 0.0;
  for (size_t n = from; n < std::min(to, x.size()); ++n) e += double(x[n]) * double(x[n]);
  return e;
}

double dB(double a, double b) {
  return 10.0 * std::log10(a / b);
}

/// The sample where |left| + |right| is largest.
size_t peakSample(const std::vector<std::vector<float>>& ir) {
  size_t peak = 0;
  for (size_t n = 0; n < ir[0].size(); ++n)
    if (std::abs(ir[0][n]) + std::abs(ir[1][n]) > std::abs(ir[0][peak]) + std::abs(ir[1][peak]))
      peak = n;
  return peak;
}

}  // namespace

// The clustering error in expectation (the bound: a source's rendered energy within 1 dB
// of its unclustered rendering), from the energy responses the IRs are synthesised from: per
// octave band, early part plus g_s^2 times the bus's late response against the whole response.
// No realisation noise enters, so the bound is the 1 dB in every band.
TEST_CASE("Hybrid rendering: each source's expected band energy within 1 dB of its own",
          "[runtime][hybrid][heavy]") {
  const auto worstBandError = [](const Rendered& r) {
    double worst = 0.0;
    for (size_t s = 0; s < r.expectedWhole.size(); ++s)
      for (int b = 0; b < kNumBands; ++b)
        worst = std::max(worst, std::abs(dB(r.expectedHybrid[s][b], r.expectedWhole[s][b])));
    return worst;
  };
  SECTION("12 sources in one room") {
    const Rendered hybrid = render(ringScene(12), Rendering::kHybrid, 6);
    REQUIRE(hybrid.buses == 4);
    CHECK(worstBandError(hybrid) < 1.0);
  }
  SECTION("Sources in two rooms: the wall keeps their late parts apart") {
    SceneDesc scene = coupledScene();
    scene.audio.lateBuses = 4;
    const Rendered hybrid = render(scene, Rendering::kHybrid, 6);
    const double worst = worstBandError(hybrid);
    WARN("two rooms, 4 buses: largest expected band difference " << worst << " dB");
    CHECK(worst < 1.0);
    for (size_t s = 0; s < hybrid.expectedWhole.size(); ++s)
      CHECK(hybrid.expectedHybrid[s].sum() == Approx(hybrid.expectedWhole[s].sum()).epsilon(1e-4));
    // The oracle can fail: one bus for both rooms gives each source the other room's spectrum.
    scene.audio.lateBuses = 1;
    const double shared = worstBandError(render(scene, Rendering::kHybrid, 6));
    WARN("two rooms, 1 bus: largest expected band difference " << shared << " dB");
    CHECK(shared > 1.0);
  }
}

// The rendered IRs, read through the audio stage: each source's broadband energy (250 Hz ..
// 8 kHz, where the stereo synthesis levels each channel to its target over 50 ms windows)
// within 0.5 dB of its whole rendering: the two renderings are independent noise realisations
// of nearly the same response, and per band their difference at 250-500 Hz reaches 1 dB by
// realisation alone (a 1.2 s IR, T60 1.2 s: about 30 degrees of freedom per octave there), so
// the per-band bound is checked in expectation above. The direct sound: the same first
// sample (it is placed exactly in both: the IR's peak) and the same left/right energy ratio
// over the 2 ms around it within 0.05 dB (its direction is exact; the reverberation under it
// differs by noise; a source panned hard has only reverberation in its far channel, whose two
// realisations differ, so there the near channel's energy is compared instead, within what
// reverberation of the far channel's level can add). The first
// non-zero sample is no instrument: the -80 dB cut ahead of the first arrival (cutLeadingResidue)
// falls where the zero-phase filters' ringing ends, which depends on the IR's length.
TEST_CASE("Hybrid rendering: rendered IRs keep each source's energy and direct sound",
          "[runtime][hybrid]") {
  const SceneDesc scene = ringScene(12);
  const Rendered whole = render(scene, Rendering::kPerSource, 6);
  const Rendered hybrid = render(scene, Rendering::kHybrid, 6);
  REQUIRE(whole.buses == 0);
  const int fs = scene.audio.sampleRate;
  for (size_t s = 0; s < scene.sources.size(); ++s) {
    double a = 0.0, b = 0.0;
    for (size_t c = 0; c < 2; ++c) {
      const Bands ea = test::bandEnergies(whole.ir[s][c], fs);
      const Bands eb = test::bandEnergies(hybrid.ir[s][c], fs);
      for (int band = 2; band < kNumBands; ++band) a += ea[band], b += eb[band];
    }
    INFO("source " << s << ": " << dB(b, a) << " dB broadband");
    CHECK(std::abs(dB(b, a)) < 0.5);
    // What the stage reports as the source's IR (wholeIrs: early part + g_s x its bus) is what
    // the audio stage plays: float rounding of the FFT convolution, relative to the peak.
    for (size_t c = 0; c < 2; ++c) {
      const std::vector<float>& played = hybrid.ir[s][c];
      const std::span<const float> reported = hybrid.stageIrs[s].channelSpan(int(c));
      float peak = 0.f, worst = 0.f;
      for (size_t n = 0; n < reported.size(); ++n) {
        peak = std::max(peak, std::abs(reported[n]));
        worst = std::max(worst, std::abs(reported[n] - played[n]));
      }
      CHECK(worst < 1e-4f * peak);
    }
    // The direct sound is each IR's peak (the ring's sources are closer than any wall's image).
    const size_t peak = peakSample(whole.ir[s]);
    CHECK(peakSample(hybrid.ir[s]) == peak);
    const size_t w = size_t(0.001 * fs), first = peak - std::min(peak, w), last = peak + w;
    const double ratioWhole =
        dB(energy(whole.ir[s][0], first, last), energy(whole.ir[s][1], first, last));
    const double ratioHybrid =
        dB(energy(hybrid.ir[s][0], first, last), energy(hybrid.ir[s][1], first, last));
    INFO("direct sound L/R " << ratioWhole << " dB whole, " << ratioHybrid << " dB hybrid");
    if (std::abs(ratioWhole) > 20.0) {
      // Panned hard: the far channel holds reverberation only, two different realisations.
      // The near channel's direct sound d is compared on its own; under it lies reverberation
      // r of about the far channel's level (rho = |r| / |d|), which adds to d with any phase:
      // each rendering's energy lies within (1 +- rho)^2 of |d|^2, so they may differ by up
      // to 20 log10((1 + rho) / (1 - rho)) dB, plus the 0.05 dB above.
      const size_t near = ratioWhole > 0.0 ? 0 : 1;
      const double rho = std::pow(10.0, -std::abs(ratioWhole) / 20.0);
      const double bound = 20.0 * std::log10((1.0 + rho) / (1.0 - rho)) + 0.05;
      INFO("near channel bound " << bound << " dB");
      CHECK(std::abs(dB(energy(hybrid.ir[s][near], first, last),
                        energy(whole.ir[s][near], first, last))) < bound);
    } else {
      CHECK(ratioHybrid == Approx(ratioWhole).margin(0.05));
    }
  }
}

// Mono hybrid rendering synthesises the sources' early parts on the tracing threads, each
// worker with its own workspace, beside the buses' job that splits the late shares: the IRs
// heard (early part plus gain times bus) must not depend on how many threads there are (a
// shared workspace written by two workers at once would change them).
TEST_CASE(
    "Hybrid rendering: mono IRs (early parts, buses, gains) the same bit for bit on 1 to "
    "3 threads",
    "[runtime][hybrid]") {
  SceneDesc scene = ringScene(9);
  scene.audio.output = OutputFormat::kMono;
  scene.audio.rendering = Rendering::kHybrid;
  const auto irs = [&](int threads) {
    SceneDesc s = scene;
    s.propagation.threads = threads;
    auto shared = std::make_shared<const SceneDesc>(s);
    PropagationStage stage(shared, s.propagation);
    REQUIRE(stage.hybrid() != nullptr);
    WorldState world;
    evaluateWorld(*shared, 0.0, world);
    for (int f = 0; f < 3; ++f) stage.traceWorld(world);
    stage.synthesizeIrs(0);
    return stage.wholeIrs(0);
  };
  const auto one = irs(1);
  REQUIRE(one.size() == 9);
  REQUIRE(energy(one[4].channelCopy(0), 0, one[4].samples()) > 0.0);
  CHECK(irs(2) == one);
  CHECK(irs(3) == one);
}

// Spatial hybrid rendering splits every source serially in source order (the late buses'
// responses are sums in that order) and synthesises the early parts in worker groups, each with
// a workspace copy of the early synthesiser, beside the buses: every sample of every source's
// early part and every bus's late IR must be the same for any number of threads, over frames
// in which the buses are kept or synthesised again. Summing the buses' responses per group (in
// an order that depends on the groups) fails this: float addition is not associative.
TEST_CASE("Hybrid rendering: spatial early parts and buses are the same bit for bit on 1 to 3 "
          "threads",
          "[runtime][hybrid][heavy]") {
  for (const OutputFormat output : {OutputFormat::kStereo, OutputFormat::kBinaural}) {
    SceneDesc scene = ringScene(9);
    scene.audio.output = output;
    scene.audio.rendering = Rendering::kHybrid;
    scene.audio.lateBuses = 2;
    const auto frames = [&](int threads) {
      SceneDesc s = scene;
      s.propagation.threads = threads;
      auto shared = std::make_shared<const SceneDesc>(s);
      PropagationStage stage(shared, s.propagation);
      REQUIRE(stage.hybrid() != nullptr);
      stage.reuseLateBuses(0.5);
      WorldState world;
      evaluateWorld(*shared, 0.0, world);
      std::vector<std::vector<ImpulseResponse>> out;
      for (int f = 0; f < 4; ++f) {
        stage.traceWorld(world);
        stage.synthesizeIrs(0);
        out.push_back(stage.lastIrs(0));
        out.push_back(stage.lastLateIrs(0));
      }
      return out;
    };
    INFO("output " << int(output));
    const auto one = frames(1);
    REQUIRE(energy(one[0][4].channelCopy(1), 0, one[0][4].samples()) > 0.0);
    REQUIRE(energy(one[1][0].channelCopy(0), 0, one[1][0].samples()) > 0.0);
    CHECK(frames(2) == one);
    CHECK(frames(3) == one);
  }
}

// Sources rendered whole are synthesised in source groups on the tracing threads, each group
// with a workspace of its own (mono: the group's first synthesiser's; spatial: a workspace copy
// of the synthesiser): every IR must be the same for any number of threads, for a first-IR
// build, its completion on the tracing threads and the frames after it. Two groups writing one
// workspace at once would change the IRs.
TEST_CASE("Sources rendered whole: the same IRs bit for bit on 1 to 3 threads",
          "[runtime][heavy]") {
  for (const OutputFormat output :
       {OutputFormat::kMono, OutputFormat::kStereo, OutputFormat::kAmbisonics}) {
    SceneDesc scene = ringScene(5);
    scene.audio.output = output;
    scene.audio.ambisonicOrder = 1;
    scene.audio.rendering = Rendering::kPerSource;
    const auto frames = [&](int threads) {
      SceneDesc s = scene;
      s.propagation.threads = threads;
      auto shared = std::make_shared<const SceneDesc>(s);
      PropagationStage stage(shared, s.propagation, audio::ConvolverLayout::Planning::kEstimate,
                             IrSynthesizer::Build::kFirstIr);
      REQUIRE(stage.hybrid() == nullptr);
      WorldState world;
      evaluateWorld(*shared, 0.0, world);
      std::vector<std::vector<ImpulseResponse>> out;
      for (int f = 0; f < 3; ++f) {
        stage.traceWorld(world);
        stage.synthesizeIrs(0);
        out.push_back(stage.lastIrs(0));
        if (f == 0) stage.completeSynthesis();
      }
      return out;
    };
    INFO("output " << int(output));
    const auto one = frames(1);
    REQUIRE(energy(one[2][3].channelCopy(0), 0, one[2][3].samples()) > 0.0);
    CHECK(frames(2) == one);
    CHECK(frames(3) == one);
  }
}
