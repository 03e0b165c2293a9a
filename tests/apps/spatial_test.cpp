// Spatial output: binaural and stereo IRs from the arrival directions of cached
// paths, with the direct sound at its exact direction.
#include <fftw3.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <vector>

#include "runtime/output_format.h"
#include "scene/orientation.h"
#include "testing/test_scenes.h"
#include "testing/test_util.h"
#include "common/input_error.h"
#include "engine/room_volume.h"
#include "engine/simulation.h"
#include "runtime/render_pipeline.h"

using dpc::test::bandEnergies;
using dpc::test::interauralDelay;

using namespace dpc;

namespace {

double db(double x) {
  return 10.0 * std::log10(x);
}

struct Rendered {
  std::vector<float> left, right;
  Bands monoEnergy;  ///< the energy response's band totals, direct included
};

/// One binaural (or stereo) frame of `scene` with the listener facing yaw (degrees).
Rendered render(SceneDesc scene, OutputFormat format, float yawDegrees, int frames = 1) {
  scene.audio.output = format;
  PropagationSettings ps = scene.propagation;
  Simulation sim(scene, ps);
  sim.enableDirectional(defaultSpatialDirections());
  Orientation o;
  o.yawRadians = yawDegrees * float(M_PI / 180.0);
  FrameInputs in = sim.inputsAt(scene.listeners[0].position);
  in.listenerOrientations = {o};
  for (int f = 0; f < frames; ++f) sim.runFrame(in);
  auto spatial = makeSpatialSynthesizer(scene, ps, roomVolume(scene.mesh));
  Rendered r;
  r.left.resize(spatial->lengthSamples());
  r.right.resize(spatial->lengthSamples());
  float* const channels[] = {r.left.data(), r.right.data()};
  spatial->synthesize(sim.directional(0), sim.result(0).direct, channels);
  r.monoEnergy = sim.result(0).energy.total() + sim.result(0).direct.intensity;
  return r;
}

/// A nearly anechoic box (absorption 0.99): the IR is the direct sound.
SceneDesc anechoic(glm::vec3 source, glm::vec3 listener) {
  SceneDesc s = test::makeShoebox({40, 40, 40}, Bands(0.99f), 1.f, source, listener, 0.5f);
  s.propagation.raysPerFrame = 256;
  s.propagation.maxOrder = 3;
  s.propagation.irLength = 0.3f;
  s.propagation.estimator = Estimator::kPathTracing;
  return s;
}

}  // namespace

TEST_CASE("Binaural: a source at the left gives ILD > 6 dB at 4 kHz and ITD 0.5-0.8 ms",
          "[spatial]") {
  // Listener facing +x (yaw 0); its left is -z (scene/scene.h: left = up x forward).
  const Rendered r = render(anechoic({20, 20, 17}, {20, 20, 20}), OutputFormat::kBinaural, 0.f);
  const Bands el = bandEnergies(r.left, 48000), er = bandEnergies(r.right, 48000);
  const double ild = db(el[6] / er[6]);
  const double itd = interauralDelay(r.left, r.right, 48000);
  INFO("ILD at 4 kHz " << ild << " dB, ITD " << itd * 1e3 << " ms");
  // Physics: a head of radius 8.75 cm gives 0.66 ms at 90 degrees (Woodworth); KEMAR's
  // measured HRIRs give 0.72 ms and ~9 dB at 4 kHz (tests/audio/hrtf_test.cpp).
  CHECK(ild > 6.0);
  CHECK(itd > 0.5e-3);
  CHECK(itd < 0.8e-3);
}

TEST_CASE("Binaural: turning the listener 180 degrees swaps the ears", "[spatial]") {
  const SceneDesc scene = anechoic({20, 20, 17}, {20, 20, 20});
  const Rendered a = render(scene, OutputFormat::kBinaural, 0.f);
  const Rendered b = render(scene, OutputFormat::kBinaural, 180.f);
  const Bands al = bandEnergies(a.left, 48000), ar = bandEnergies(a.right, 48000);
  const Bands bl = bandEnergies(b.left, 48000), br = bandEnergies(b.right, 48000);
  // KEMAR is left-right symmetric (hrtf_test: 4e-6 relative); what remains is the sparse
  // diffuse part of a nearly anechoic box: 1 dB.
  for (int band = 2; band < kNumBands; ++band) {
    INFO("band " << band << ": L " << db(al[band]) << " R " << db(ar[band]) << " | turned L "
                 << db(bl[band]) << " R " << db(br[band]));
    CHECK(std::abs(db(al[band] / br[band])) < 1.0);
    CHECK(std::abs(db(ar[band] / bl[band])) < 1.0);
  }
  CHECK(db(al[6] / ar[6]) > 6.0);
  CHECK(db(br[6] / bl[6]) > 6.0);
}

TEST_CASE("Binaural band energies average to the mono energy response within 2 dB",
          "[spatial][heavy]") {
  // A reverberant shoebox, source 5 m away: the diffuse field carries most of the energy.
  SceneDesc scene = test::makeShoebox({10, 3, 7}, Bands(0.15f), 0.7f, {2, 1.5f, 2}, {7, 1.6f, 5});
  scene.propagation.raysPerFrame = 4096;
  scene.propagation.maxOrder = 200;
  scene.propagation.irLength = 1.5f;
  const Rendered r = render(scene, OutputFormat::kBinaural, 30.f, 10);
  // The extreme bands over their octave only: beyond it (below 44 Hz, above 11.3 kHz) the IR
  // carries the octave's spectral density on, as an exact IR would (synthesis/spatial_synthesizer.h).
  const Bands el = bandEnergies(r.left, 48000, true), er = bandEnergies(r.right, 48000, true);
  // Tolerance 2 dB (the issue's): the synthesis preserves band energy in expectation; one
  // realisation fluctuates by ~1 dB at 63 Hz (ir_synthesis_test), and the direct sound keeps
  // its direction's HRTF colouration relative to the diffuse-field equalisation.
  for (int b = 0; b < kNumBands; ++b) {
    const double avg = 0.5 * (double(el[b]) + double(er[b]));
    INFO("band " << b << ": ears " << db(avg) << " dB, mono " << db(r.monoEnergy[b]) << " dB");
    CHECK(std::abs(db(avg / r.monoEnergy[b])) < 2.0);
  }
}

TEST_CASE("Stereo: constant-power panning puts a left source in the left channel", "[spatial]") {
  const Rendered r = render(anechoic({20, 20, 17}, {20, 20, 20}), OutputFormat::kStereo, 0.f);
  const Bands el = bandEnergies(r.left, 48000), er = bandEnergies(r.right, 48000);
  CHECK(db(el.sum() / er.sum()) > 15.0);  // hard left: g_R = cos(90 deg) = 0 for the direct
  // Facing the source: equal channels.
  const Rendered f = render(anechoic({23, 20, 20}, {20, 20, 20}), OutputFormat::kStereo, 0.f);
  const Bands fl = bandEnergies(f.left, 48000), fr = bandEnergies(f.right, 48000);
  CHECK(std::abs(db(fl.sum() / fr.sum())) < 0.5);
}

TEST_CASE("An invalid SOFA file is a clear error naming the file", "[spatial]") {
  namespace fs = std::filesystem;
  const fs::path bad = fs::temp_directory_path() / "dpc_not_a_sofa_file.sofa";
  std::ofstream(bad) << "this is not HDF5\n";
  SceneDesc scene = anechoic({20, 20, 17}, {20, 20, 20});
  scene.path = "room.json";
  scene.audio.output = OutputFormat::kBinaural;
  scene.audio.hrtfPath = bad.string();
  try {
    makeSpatialSynthesizer(scene, scene.propagation, 1000.0);
    FAIL("no error for an invalid SOFA file");
  } catch (const InputError& e) {
    const std::string what = e.what();
    INFO(what);
    CHECK(what.find("room.json: audio.hrtf") != std::string::npos);
    CHECK(what.find("dpc_not_a_sofa_file.sofa") != std::string::npos);
  }
  fs::remove(bad);
}
