// Time to first sound as a host sees it: a live session is started and its audio callback
// called at the block rate, as a device would; the first block holding a sample other than 0
// is what SessionStatus::firstSoundSeconds reports (NaN before it), and the first frame that
// produced it traced the adaptive controller's floor, not the scene's rays, so that it came
// sooner. The oracle is the test's own: it scans the blocks it receives for the first sound.
#include <catch2/catch.hpp>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <mutex>
#include <thread>
#include <vector>

#include "common/fftw_util.h"
#include "common/fftw_wisdom.h"
#include "runtime/adaptive_rays.h"
#include "runtime/live_session.h"
#include "runtime/propagation_stage.h"
#include "scene/scene.h"
#include "scene/trajectory.h"
#include "testing/temp_dir.h"
#include "testing/test_scenes.h"

using namespace dpc;

namespace {

/// Calls the started session's render at the block rate, as a device would, until done(block
/// just rendered holds sound) returns true or 30 s passed. Returns whether done() did.
template <class Done>
bool renderUntil(LiveSession& session, Done done) {
  std::vector<float> left(size_t(session.blockSize())), right(left.size());
  float* out[2] = {left.data(), right.data()};
  const auto start = std::chrono::steady_clock::now();
  const double block = double(session.blockSize()) / session.sampleRate();
  while (std::chrono::steady_clock::now() - start < std::chrono::seconds(30)) {
    const auto before = std::chrono::steady_clock::now();
    session.render(nullptr, out, session.blockSize());
    bool sound = false;
    for (size_t i = 0; i < left.size() && !sound; ++i) sound = left[i] != 0.f || right[i] != 0.f;
    if (done(sound, before)) return true;
    std::this_thread::sleep_for(std::chrono::duration<double>(block));
  }
  return false;
}

}  // namespace

TEST_CASE(
    "Live session: the first block with sound is timed, its frame traced a quarter of the rays",
    "[live]") {
  SceneDesc scene = loadScene(std::string(DPC_SOURCE_DIR) + "/scenes/shoebox.json");
  const DrySignals dry = loadDrySignals(scene);
  PropagationSettings ps = scene.propagation;
  ps.raysPerFrame = 4096;
  // A 1 s frame period and no latency target: nothing but the first frame lowers the rays.
  ps.frameRate = 1.f;
  LiveSession::Options o;
  o.latencyTargetSeconds = 0.0;
  LiveSession session(test::shared(scene), ps, test::shared(dry), o);
  CHECK(std::isnan(session.status().firstSoundSeconds));
  const auto start = std::chrono::steady_clock::now();
  session.start();
  double heardAfter = 0.0;  // seconds from start, by the test's clock
  const bool heard = renderUntil(session, [&](bool sound, auto blockStart) {
    if (sound) heardAfter = std::chrono::duration<double>(blockStart - start).count();
    return sound;
  });
  session.stop();
  REQUIRE(heard);
  const LiveSession::Status st = session.status();
  REQUIRE(std::isfinite(st.firstSoundSeconds));
  // The session's start is stamped after the test's clock starts and its block before the
  // test's scan: 0 < reported <= what the test measured.
  CHECK(st.firstSoundSeconds > 0.0);
  CHECK(st.firstSoundSeconds <= heardAfter + 1e-3);
  const AdaptiveRays controller(ps.raysPerFrame, 1.0 / ps.frameRate);
  CHECK(st.raysPerFrameMin == controller.firstFrameRays());
  CHECK(st.raysPerFrameScene == 4096);
  // The synthesisers were built for the first IR and completed after its frame.
  CHECK(std::isfinite(st.synthesisCompletionSeconds));
}

namespace {

/// Each source's whole IR of the second frame at the scene's start (t = 0) from a stage built
/// `build`, which completes its synthesisers after the first frame; the first frame's IRs
/// into `first`.
std::vector<ImpulseResponse> stageIrs(const SceneDesc& scene, IrSynthesizer::Build build,
                                      std::vector<ImpulseResponse>& first) {
  const auto shared = test::shared(scene);
  PropagationStage stage(shared, scene.propagation, audio::ConvolverLayout::Planning::kEstimate,
                         build);
  CHECK(stage.synthesisCompleted() == (build == IrSynthesizer::Build::kComplete));
  WorldState world;
  evaluateWorld(*shared, 0.0, world);
  stage.traceWorld(world);
  stage.synthesizeIrs(0);
  first = stage.wholeIrs(0);
  stage.completeSynthesis();
  CHECK(stage.synthesisCompleted());
  stage.traceWorld(world);
  stage.synthesizeIrs(0);
  return stage.wholeIrs(0);
}

double irEnergy(const ImpulseResponse& ir) {
  double e = 0.0;
  for (int c = 0; c < ir.channels(); ++c)
    for (size_t n = 0; n < ir.samples(); ++n) e += double(ir.channel(c)[n]) * ir.channel(c)[n];
  return e;
}

}  // namespace

// A live session builds its synthesisers with what the first IR needs and completes them after
// the first frame (LiveSession::Options::quickFirstIr). Oracle: a stage built complete from the
// same scene and seed, whose frames trace the same paths bit for bit: from the second frame on
// the IRs must be its bits; the first IR is another realisation of the same responses (its
// bands' sequences and windows not levelled), so its energy is the complete build's within
// the realisation's scatter.
TEST_CASE("A first-IR build plays the complete build's IRs from its second frame on", "[live]") {
  for (const char* name : {"two_rooms", "market"}) {
    SceneDesc scene = loadScene(std::string(DPC_SOURCE_DIR) + "/scenes/" + name + ".json");
    scene.propagation.raysPerFrame = 512;
    INFO(name);
    std::vector<ImpulseResponse> quickFirst, completeFirst;
    const auto quick = stageIrs(scene, IrSynthesizer::Build::kFirstIr, quickFirst);
    const auto complete = stageIrs(scene, IrSynthesizer::Build::kComplete, completeFirst);
    REQUIRE(quick.size() == scene.sources.size());
    REQUIRE(irEnergy(complete[0]) > 0.0);
    CHECK(quick == complete);
    // The first IRs differ (what the complete build adds changes the realisation) ...
    CHECK_FALSE(quickFirst == completeFirst);
    // ... but not in energy: the envelope sets each band's energy in expectation either way,
    // and a broadband IR of a reverberant response holds thousands of degrees of freedom (its
    // energy scatters by a few per cent); the levelling moves no band's energy by 1 dB
    // (window_leveller.h), so every source's IR is within 1 dB of the complete build's.
    for (size_t s = 0; s < quickFirst.size(); ++s) {
      INFO("source " << s);
      CHECK(std::abs(10.0 * std::log10(irEnergy(quickFirst[s]) / irEnergy(completeFirst[s]))) <
            1.0);
    }
  }
}

// A stepped session (a host's deterministic rendering) completes its synthesisers before its
// first frame: its IRs are a complete build's from the first step on.
TEST_CASE("A stepped live session's IRs are a complete build's from the first step", "[live]") {
  SceneDesc scene = loadScene(std::string(DPC_SOURCE_DIR) + "/scenes/shoebox.json");
  scene.propagation.raysPerFrame = 512;
  const DrySignals dry = loadDrySignals(scene);
  const auto firstIr = [&](bool quick) {
    LiveSession::Options o;
    o.quickFirstIr = quick;
    LiveSession session(test::shared(scene), scene.propagation, test::shared(dry), o);
    REQUIRE(session.step());
    ImpulseResponse ir;
    REQUIRE(session.copyResponses(0, [&](const LiveSession::Responses& r) { ir = *r.ir; }));
    return ir;
  };
  const ImpulseResponse quick = firstIr(true);
  REQUIRE(quick.samples() > 0);
  CHECK(quick == firstIr(false));
}

// Measured FFT plans without wisdom for them (the first run on a machine): the session starts
// with estimated plans (no planner before the first sound) and measures them on a thread of its
// own after the first frame, swapping them in while it plays; it keeps playing sound, finite.
TEST_CASE("A live session without FFT wisdom plays at once and measures its plans meanwhile",
          "[live][fftw]") {
  const test::TempDir dir("first_sound_test_wisdom");
  REQUIRE(setenv("DPC_FFTW_WISDOM", (dir.path() / "wisdom").c_str(), 1) == 0);
  {
    std::lock_guard lock(fftwPlannerMutex());
    importFftwWisdomOnce();
    fftwf_forget_wisdom();  // nothing this process measured before
  }
  SceneDesc scene = loadScene(std::string(DPC_SOURCE_DIR) + "/scenes/shoebox.json");
  scene.propagation.raysPerFrame = 512;
  const DrySignals dry = loadDrySignals(scene);
  LiveSession::Options o;
  o.measureFftPlans = true;
  LiveSession session(test::shared(scene), scene.propagation, test::shared(dry), o);
  CHECK_FALSE(session.fftPlansMeasured());
  session.start();
  CHECK(renderUntil(session, [](bool sound, auto) { return sound; }));
  CHECK(renderUntil(session, [&](bool, auto) { return session.fftPlansMeasured(); }));
  // Sound after the swap: the next blocks with the measured plans.
  int sounding = 0;
  CHECK(renderUntil(session, [&](bool sound, auto) { return (sounding += sound) >= 10; }));
  session.stop();
  CHECK(session.status().nanBlocks == 0);
  unsetenv("DPC_FFTW_WISDOM");
}
