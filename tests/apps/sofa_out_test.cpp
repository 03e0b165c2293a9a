// --ir-out FILE.sofa: an offline render's last-frame IRs written as AES69 GeneralFIR and read
// back with libmysofa (an independent HDF5 reader), against the same IRs written as WAV.
#include <mysofa.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <string>

#include "apps/demo/sofa_out.h"
#include "audio/wav_io.h"
#include "runtime/dry_signals.h"
#include "runtime/offline_renderer.h"
#include "scene/scene.h"
#include "testing/temp_dir.h"
#include "testing/test_scenes.h"

using namespace dpc;

namespace {

const std::string kScenes = std::string(DPC_SOURCE_DIR) + "/scenes";

struct Loaded {
  MYSOFA_HRTF* h = nullptr;
  explicit Loaded(const std::string& path) {
    int err = 0;
    h = mysofa_load(path.c_str(), &err);
    INFO("mysofa_load error " << err);
    REQUIRE(h != nullptr);
  }
  ~Loaded() { mysofa_free(h); }
  std::string attribute(const char* name) const {
    const char* v = mysofa_getAttribute(h->attributes, const_cast<char*>(name));
    return v ? v : "";
  }
};

}  // namespace

TEST_CASE("SOFA output: dimensions, positions and samples read back with libmysofa",
          "[sofa]") {
  SceneDesc scene = loadScene(kScenes + "/shoebox.json");
  scene.audio.output = OutputFormat::kAmbisonics;
  scene.audio.ambisonicOrder = 1;
  PropagationSettings ps = scene.propagation;
  ps.raysPerFrame = 2000;
  ps.irLength = 0.3f;
  OfflineOptions opt;
  opt.durationSeconds = 0.3;
  const OfflineResult res =
      renderOffline(test::shared(scene), ps, test::shared(loadDrySignals(scene)), opt);
  const OfflineListenerResult& r = res.listeners.at(0);
  test::TempDir dir("sofa_out_test");
  const std::string sofa = (dir.path() / "ir.sofa").string();
  const std::string wav = (dir.path() / "ir.wav").string();
  demo::stageIrSofa(scene, r, sofa).commit();
  audio::AudioData ir;
  ir.sampleRate = scene.audio.sampleRate;
  for (const ImpulseResponse& source : r.lastIrs)
    for (int c = 0; c < source.channels(); ++c) ir.channels.push_back(source.channelCopy(c));
  audio::stageWav(wav, ir).commit();

  const Loaded f(sofa);
  const MYSOFA_HRTF& h = *f.h;
  const size_t M = r.lastIrs.size(), R = size_t(r.lastIrs[0].channels()),
               N = r.lastIrs[0].samples();
  CHECK(M == scene.sources.size());
  CHECK(R == 4);  // order 1: (1 + 1)^2
  CHECK(h.M == M);
  CHECK(h.R == R);
  CHECK(h.N == N);
  CHECK(h.E == 1);
  CHECK(h.C == 3);
  CHECK(h.I == 1);
  CHECK(f.attribute("Conventions") == "SOFA");
  CHECK(f.attribute("SOFAConventions") == "GeneralFIR");
  CHECK(f.attribute("DataType") == "FIR");
  REQUIRE(h.DataSamplingRate.elements == 1);
  CHECK(h.DataSamplingRate.values[0] == float(scene.audio.sampleRate));
  // Positions: the scene's (y up) in SOFA's frame (z up): (x, -z, y).
  const glm::vec3 src = r.lastSourcePositions[0], lis = r.lastListenerPosition;
  REQUIRE(h.SourcePosition.elements == 3 * M);
  CHECK(h.SourcePosition.values[0] == Approx(src.x).margin(1e-5));
  CHECK(h.SourcePosition.values[1] == Approx(-src.z).margin(1e-5));
  CHECK(h.SourcePosition.values[2] == Approx(src.y).margin(1e-5));
  REQUIRE(h.ListenerPosition.elements == 3);
  CHECK(h.ListenerPosition.values[0] == Approx(lis.x).margin(1e-5));
  CHECK(h.ListenerPosition.values[1] == Approx(-lis.z).margin(1e-5));
  CHECK(h.ListenerPosition.values[2] == Approx(lis.y).margin(1e-5));
  REQUIRE(h.ListenerUp.elements == 3);
  CHECK(h.ListenerUp.values[2] == Approx(1.0).margin(1e-5));  // level head: z up
  REQUIRE(h.ListenerView.elements == 3);
  const glm::vec3 fw = r.lastListenerOrientation.forward();
  CHECK(h.ListenerView.values[0] == Approx(fw.x).margin(1e-5));
  CHECK(h.ListenerView.values[1] == Approx(-fw.z).margin(1e-5));
  // Samples: the WAV's float32 samples, exactly (float -> double -> libmysofa's float).
  const audio::AudioData back = audio::readWav(wav);
  REQUIRE(h.DataIR.elements == M * R * N);
  REQUIRE(back.channels.size() == M * R);
  size_t differing = 0;
  for (size_t c = 0; c < M * R; ++c)
    for (size_t i = 0; i < N; ++i)
      differing += h.DataIR.values[c * N + i] != back.channels[c][i];
  CHECK(differing == 0);
}
