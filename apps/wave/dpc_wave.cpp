// dpc-wave: the low band of a scene by wave simulation (docs/wave.md): one source's
// band-limited impulse response at one or every listener, as the FDTD grid computes it, before
// any crossover (dpc-demo --ir-out joins it to the ray-traced IR when the scene's
// wave.enabled is true).
//
//   dpc-wave SCENE --out IR.wav [--source N] [--listener NAME] [--seconds S]
//            [--max-frequency HZ] [--grid-spacing M] [--json]
//   mpirun -np N dpc-wave ...   (N ranks share each simulation by slabs; the same file, bit
//                                for bit, written by rank 0)
//
// Main thread (TBB workers inside). Bad input: one line "FILE: FIELD: problem" (or
// "command line: --flag: problem") on stderr (rank 0), exit status 1, no file written.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "apps/cli_values.h"
#include "apps/mpi/cluster.h"
#include "audio/wav_io.h"
#include "common/input_error.h"
#include "common/output_file.h"
#include "common/program_main.h"
#include "common/stop_signals.h"
#include "scene/limits.h"
#include "scene/scene.h"
#include "scene/validate.h"
#include "wave/scene_wave.h"

namespace dpc {
namespace {

struct Options {
  std::string scene, out;
  int64_t source = 0;  // signed, so that "-1" is named as given, not as 2^64 - 1
  std::string listener;
  std::optional<double> seconds, maxFrequency, gridSpacing;
  bool json = false;
};

constexpr const char* kDescription =
    "dpc-wave: the low band of a scene by wave simulation (FDTD, docs/wave.md).\n"
    "Writes one source's band-limited impulse response at the listeners (one channel each,\n"
    "in scene order, or the one named), in dpc's IR units (a free-field path of length r is a\n"
    "band-limited Dirac of area 1/(sqrt(4 pi) r): energy 1/(4 pi r^2), the energy response's\n"
    "scale), before any crossover. The scene's `wave` keys set\n"
    "the maximum frequency and grid; dpc-demo --ir-out joins the band to the ray-traced IR\n"
    "when wave.enabled is true. Prints the grid, the cost and progress with an ETA.\n"
    "Exit status: 0 on success, 1 on bad input (message on stderr).";

/// The MPI job's ranks as the wave solver's processes.
class ClusterSlabLink final : public wave::SlabLink {
 public:
  explicit ClusterSlabLink(Cluster& cluster) : cluster_(cluster) {}
  int rank() const override { return cluster_.rank(); }
  int size() const override { return cluster_.size(); }
  void exchange(std::span<const float> toLower, std::span<float> fromLower,
                std::span<const float> toUpper, std::span<float> fromUpper) override {
    cluster_.exchangeWithNeighbours(toLower, fromLower, toUpper, fromUpper);
  }
  void broadcast(std::span<float> data, int owner) override { cluster_.broadcast(data, owner); }

 private:
  Cluster& cluster_;
};

void addOptions(CLI::App& app, Options& o) {
  app.add_option("SCENE", o.scene, "Scene file (JSON)")->required()->type_name("FILE");
  app.add_option("--out", o.out, "Output WAV (float32, the scene's sample rate)")
      ->required()
      ->type_name("FILE");
  app.add_option("--source", o.source, "Source index (0 = first)")->type_name("N");
  app.add_option("--listener", o.listener, "Only this listener (by name; default: every one)")
      ->type_name("NAME");
  app.add_option("--seconds", o.seconds,
                 "IR length in seconds, (0, 60] (default: the scene's propagation.ir_length)")
      ->type_name("S");
  app.add_option("--max-frequency", o.maxFrequency, "Overrides wave.max_frequency (Hz)")
      ->type_name("HZ");
  app.add_option("--grid-spacing", o.gridSpacing, "Overrides wave.grid_spacing (m)")
      ->type_name("M");
  app.add_flag("--json", o.json, "Print the grid and the cost as JSON on stdout");
}

/// The scene with the command line's overrides, checked as the scene file is.
SceneDesc loadWithOverrides(const Options& o) {
  SceneDesc scene = loadScene(o.scene);
  if (o.maxFrequency) {
    scene.wave.maxFrequencyHz = checkFloatField("wave.max_frequency", *o.maxFrequency,
                                                Origin{"command line", {}}, "--max-frequency");
  }
  if (o.gridSpacing) {
    scene.wave.gridSpacingM = checkFloatField("wave.grid_spacing", *o.gridSpacing,
                                              Origin{"command line", {}}, "--grid-spacing");
  }
  validate(scene, Origin{"command line", {}});
  if (o.source < 0 || uint64_t(o.source) >= scene.sources.size())
    throw InputError("command line", "--source",
                     std::to_string(o.source) + " is not a source index (the scene has " +
                         std::to_string(scene.sources.size()) + ")");
  if (o.seconds && !(*o.seconds > 0.0 && *o.seconds <= 60.0))
    throw InputError("command line", "--seconds", "must be in (0, 60] s");
  // The IR's samples (wave::sceneWaveBand rounds the length to whole samples).
  const double seconds = o.seconds.value_or(double(scene.propagation.irLength));
  if (std::llround(seconds * scene.audio.sampleRate) < 1)
    throw InputError(o.seconds ? "command line" : scene.path,
                     o.seconds ? "--seconds" : "propagation.ir_length",
                     valueText(seconds) + " s is shorter than one sample at " +
                         std::to_string(scene.audio.sampleRate) + " Hz");
  return scene;
}

/// Progress on stderr with an estimate of the time left.
void progress(size_t done, size_t total, std::chrono::steady_clock::time_point t0) {
  static int lastPercent = -1;
  const int percent = int(100.0 * double(done) / double(total));
  if (percent == lastPercent) return;
  lastPercent = percent;
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double left = done ? elapsed * double(total - done) / double(done) : 0.0;
  if (isatty(STDERR_FILENO))
    std::fprintf(stderr, "\rwave: %3d%%  step %zu / %zu  ETA %.0f s   %s", percent, done, total,
                 left, done == total ? "\n" : "");
  else if (percent % 10 == 0)
    std::fprintf(stderr, "wave: %3d%%  step %zu / %zu  ETA %.0f s\n", percent, done, total, left);
}

void report(const wave::WaveBandStats& s, const SceneDesc& scene, double seconds, bool json) {
  const auto& g = s.layout;
  const double volume = double(s.airNodes) * g.spacing.x * g.spacing.y * g.spacing.z;
  if (json) {
    std::printf(
        "{\"max_frequency_hz\": %g, \"spacing_m\": [%g, %g, %g], \"nodes\": [%d, %d, %d], "
        "\"air_nodes\": %zu, \"air_volume_m3\": %g, \"boundary_nodes\": %zu, \"step_rate_hz\": %d, "
        "\"steps\": %zu, \"simulations\": %zu, \"seconds\": %g, \"state_bytes\": %zu, "
        "\"build_s\": %g, \"simulate_s\": %g, \"processes\": %d}\n",
        double(scene.wave.maxFrequencyHz), g.spacing.x, g.spacing.y, g.spacing.z, g.count[0],
        g.count[1], g.count[2], s.airNodes, volume, s.boundaryNodes, s.stepRate, s.steps,
        s.simulations, seconds, s.stateBytes, s.buildSeconds, s.simulateSeconds, s.processes);
    return;
  }
  std::printf("grid %d x %d x %d nodes, spacing %.4f x %.4f x %.4f m, air %zu nodes (%.1f m^3), "
              "%zu on walls\n",
              g.count[0], g.count[1], g.count[2], g.spacing.x, g.spacing.y, g.spacing.z,
              s.airNodes, volume, s.boundaryNodes);
  std::printf("%zu simulation(s) (one per octave band) of %zu steps at %d Hz (%.2f s), state "
              "%.1f MB per process, grid %.2f s, simulation %.2f s on %d process(es)\n",
              s.simulations, s.steps, s.stepRate, seconds, double(s.stateBytes) / 1e6,
              s.buildSeconds, s.simulateSeconds, s.processes);
}

/// A grid too large for the spacing a flag set names the flag, not the scene file's field.
[[noreturn]] void rethrowForFlag(const Options& o, const InputError& e) {
  if (e.file() == o.scene && e.field() == "wave.grid_spacing" && o.gridSpacing)
    throw InputError("command line", "--grid-spacing", e.problem());
  if (e.file() == o.scene && e.field() == "wave.max_frequency" && o.maxFrequency)
    throw InputError("command line", "--max-frequency", e.problem());
  throw e;
}

int simulate(const Options& o, Cluster& cluster);

int run(const Options& o, Cluster& cluster) {
  try {
    return simulate(o, cluster);
  } catch (const InputError& e) {
    rethrowForFlag(o, e);
  }
}

int simulate(const Options& o, Cluster& cluster) {
  const SceneDesc scene = loadWithOverrides(o);
  const bool writer = cluster.rank() == 0;
  // Alone, a temporary is made and removed beside --out before the simulation; under mpirun
  // every rank takes this path, and a rank whose file system refused it would leave the
  // others waiting in the simulation's exchanges.
  if (cluster.size() == 1)
    checkOutputCreatable(o.out, "--out", sceneInputFiles(scene, o.scene));
  else
    checkOutputPath(o.out, "--out", sceneInputFiles(scene, o.scene));
  checkOutputFormat("--out", o.out, {"WAV"});  // after the path's checks, as dpc-demo's
  std::vector<size_t> listeners;
  if (!o.listener.empty())
    listeners.push_back(listenerIndex(scene, o.listener, "--listener"));
  else
    for (size_t l = 0; l < scene.listeners.size(); ++l) listeners.push_back(l);
  wave::WaveBandOptions opt;
  opt.seconds = o.seconds.value_or(double(scene.propagation.irLength));
  opt.sampleRate = scene.audio.sampleRate;
  const auto t0 = std::chrono::steady_clock::now();
  // Alone, a stop signal ends the run at the next step with one line and 128 + its number, no
  // file written (common/stop_signals.h); under mpirun the ranks keep mpirun's handling.
  const bool alone = cluster.size() == 1;
  if (alone) catchStopSignals();
  if (writer)
    opt.progress = [t0, alone](size_t done, size_t total) {
      if (alone) throwIfStopped();
      progress(done, total, t0);
    };
  ClusterSlabLink link(cluster);
  if (cluster.size() > 1) opt.link = &link;
  const wave::WaveBand band = wave::sceneWaveBand(scene, size_t(o.source), listeners, 0.0, opt);
  if (!writer) return 0;
  if (alone) throwIfStopped();
  audio::AudioData ir;
  ir.sampleRate = scene.audio.sampleRate;
  ir.channels = band.irs;
  audio::writeWav(o.out, ir, audio::SampleFormat::kFloat32);
  report(band.stats, scene, opt.seconds, o.json);
  if (!o.json) std::printf("wrote %s (%zu channel(s))\n", o.out.c_str(), ir.channels.size());
  return 0;
}

}  // namespace
}  // namespace dpc

int main(int argc, char** argv) {
  return dpc::runReportingErrors("dpc-wave", [&] {
    dpc::Cluster cluster(argc, argv);
    dpc::Options o;
    CLI::App app(dpc::kDescription, "dpc-wave");
    dpc::addOptions(app, o);
    dpc::refuseEmptyValues(app);
    int parsed = 1;  // 1: parsed, 0: help printed, -1: a command-line error (printed by rank 0)
    try {
      app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
      parsed = e.get_exit_code() == 0 ? 0 : -1;
      if (cluster.rank() == 0) {
        if (parsed == 0) app.exit(e);
        else std::fprintf(stderr, "dpc-wave: command line: %s\n", e.what());
      }
    }
    if (parsed <= 0) return parsed == 0 ? 0 : 1;
    if (dpc::together(cluster, "dpc-wave", [&] { return dpc::run(o, cluster); })) return 0;
    return dpc::stopSignal() != 0 ? 128 + dpc::stopSignal() : 1;  // the line is printed
  });
}
