// dpc-demo --offline: streams each listener's render to a temporary WAV and levels it, writes
// the last frame's IR and energy response if asked, and renames every output into place
// together once all are complete. SIGINT, SIGTERM and SIGHUP stop the render between blocks:
// every temporary is removed, no output is touched (common/stop_signals.h).
#include "apps/demo/run_offline.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "analysis/energy_response_csv.h"
#include "apps/demo/bake_flag.h"
#include "apps/demo/output_paths.h"
#include "apps/demo/overrides.h"
#include "apps/demo/preflight.h"
#include "apps/demo/sofa_out.h"
#include "apps/demo/status_line.h"
#include "apps/demo/studio_offline.h"
#include "audio/wav_io.h"
#include "common/input_error.h"
#include "common/output_file.h"
#include "common/stop_signals.h"
#include "runtime/offline_renderer.h"
#include "runtime/output_format.h"

namespace dpc::demo {
namespace {

using Writers = std::vector<std::unique_ptr<audio::WavStreamWriter>>;

/// Progress on stderr: a bar redrawn in place on a terminal, a line per 10 % otherwise.
void progressBar(double done, double total) {
  const int width = 40;
  const double f = total > 0 ? std::min(1.0, done / total) : 1.0;
  const int filled = int(f * width);
  if (isatty(STDERR_FILENO)) {
    std::fprintf(stderr, "\r[%.*s%*s] %3d%%  %.1f / %.1f s", filled,
                 "########################################", width - filled, "", int(f * 100), done,
                 total);
    if (f >= 1.0) std::fprintf(stderr, "\n");
  } else if (int(f * 100) % 10 == 0) {
    std::fprintf(stderr, "progress %3d%%  %.1f / %.1f s\n", int(f * 100), done, total);
  }
}

/// Loads the scene's overrides and checks everything that can be checked before rendering:
/// the settings, --duration and --gain-db, the output paths, the signals, the workload.
PropagationSettings prepareOffline(SceneDesc& scene, const Flags& fl) {
  applyAudioOverrides(scene, fl);
  printSceneWarnings(scene);
  const PropagationSettings settings = applyOverrides(scene, fl);
  checkDuration(fl);
  if (fl.gainDb && !(*fl.gainDb >= -120.0 && *fl.gainDb <= 60.0))
    throw InputError("command line", "--gain-db", "must be a number in [-120, 60] dB");
  checkOutputs(scene, fl);
  requireSignal(scene);
  // Work and memory first (loading many or long signals takes time), then with the length.
  checkSetup(scene, settings, fl.duration.value_or(0.0), false);
  return settings;
}

/// One streaming writer per listener. Each listener streams to a temporary file next to its
/// output (memory independent of the duration), renamed into place only once complete; a
/// failed render leaves no file.
Writers openWriters(const SceneDesc& scene, const std::vector<OutputPaths>& paths) {
  Writers writers;
  for (const OutputPaths& p : paths)
    writers.push_back(std::make_unique<audio::WavStreamWriter>(p.audio, scene.audio.sampleRate,
                                                               renderedChannels(scene.audio),
                                                               audio::SampleFormat::kFloat32));
  return writers;
}

/// The name of the scene's output format as printed.
const char* formatName(OutputFormat format) {
  return format == OutputFormat::kBinaural            ? "binaural"
         : format == OutputFormat::kStereo            ? "stereo"
         : format == OutputFormat::kAmbisonics        ? "ambisonics (AmbiX)"
         : format == OutputFormat::kAmbisonicBinaural ? "binaural, head-tracked from Ambisonics"
         : format == OutputFormat::kLoudspeakers      ? "loudspeakers (VBAP)"
                                                      : "mono";
}

/// --ir-out and --er-out of one listener: its last frame's IRs (WAV: all channels,
/// source-major; .sofa: apps/demo/sofa_out.h) and energy responses, complete temporaries added to
/// `outputs`.
void stageLastFrame(const SceneDesc& scene, const OfflineListenerResult& r,
                    const OutputPaths& paths, OutputSet& outputs) {
  if (!paths.ir.empty() && isSofaPath(paths.ir)) {
    outputs.add(stageIrSofa(scene, r, paths.ir));
  } else if (!paths.ir.empty()) {
    audio::AudioData ir;
    ir.sampleRate = scene.audio.sampleRate;
    for (const ImpulseResponse& source : r.lastIrs)
      for (int c = 0; c < source.channels(); ++c) ir.channels.push_back(source.channelCopy(c));
    outputs.add(audio::stageWav(paths.ir, ir, audio::SampleFormat::kFloat32));
  }
  if (!paths.energy.empty()) {
    std::vector<SourceEnergy> er;
    for (size_t s = 0; s < r.lastEnergy.size(); ++s)
      er.push_back({r.lastEnergy[s], r.lastDirect[s]});
    outputs.add(stageEnergyCsv(paths.energy, er));
  }
}

/// What one listener's files hold, said once they are in place.
struct StagedListener {
  size_t frames = 0;
  double gainDb = 0.0;
};

/// Finishes one listener's render streamed into `writer` (level: peak normalised to -1 dBFS
/// by a second streaming pass, or --gain-db already applied) and adds it, with its --ir-out /
/// --er-out files, to `outputs` (nothing renamed yet).
/// signalsSilent: every dry signal is (allSignalsSilent, warned about when loaded), so a
/// silent render is no sign of a geometry problem. loudestDry: loudestSignalPeak.
StagedListener stageListener(const Flags& fl, const SceneDesc& scene,
                             const OfflineListenerResult& r, audio::WavStreamWriter& writer,
                             const OutputPaths& paths, OutputSet& outputs, bool signalsSilent,
                             float loudestDry) {
  const float peak = writer.peak();
  const bool silent = peak < kSilentPeak;
  const bool rounding = !silent && double(peak) < kRoundingPeakRatio * double(loudestDry);
  if (silent && !signalsSilent)
    std::fprintf(stderr,
                 "warning: %s: the render of listener \"%s\" is silent (empty energy response: "
                 "is the listener inside the mesh and each source inside the room?)\n",
                 fl.scene.c_str(), r.name.c_str());
  if (rounding)
    std::fprintf(stderr,
                 "warning: %s: the render of listener \"%s\" peaks %.0f dB below its loudest dry "
                 "signal: rounding, not sound (does it end before any sound arrives?); not "
                 "normalised\n",
                 fl.scene.c_str(), r.name.c_str(), 20.0 * std::log10(double(loudestDry) / peak));
  double gainDb = fl.gainDb.value_or(0.0);
  if (!fl.gainDb) {
    gainDb = silent || rounding ? 0.0 : -1.0 - 20.0 * std::log10(peak);  // silence stays
    writer.rescale(float(std::pow(10.0, gainDb / 20.0)));
  }
  const StagedListener staged{writer.frames(), gainDb};
  outputs.add(writer.finish());
  stageLastFrame(scene, r, paths, outputs);
  return staged;
}

/// Says what one listener's files hold, once they are in place.
void printWritten(const SceneDesc& scene, const OfflineListenerResult& r,
                  const StagedListener& staged, const OutputPaths& paths) {
  const double audioSeconds = double(staged.frames) / scene.audio.sampleRate;
  std::printf("wrote %s (%.2f s, %d Hz, %s, float32, gain %+.1f dB)\n", paths.audio.c_str(),
              audioSeconds, scene.audio.sampleRate, formatName(scene.audio.output), staged.gainDb);
  if (!paths.energy.empty())
    std::printf("wrote %s (last frame's energy response, %zu source(s))\n", paths.energy.c_str(),
                r.lastEnergy.size());
  if (!paths.ir.empty())
    std::printf("wrote %s (last frame's IR, %zu channel(s): source-major)\n", paths.ir.c_str(),
                r.lastIrs.size() * size_t(r.lastIrs.front().channels()));
}

/// One line per propagation run (shared by every listener it rendered).
void printTotals(const OfflineResult& r, double audioSeconds) {
  const auto& t = r.totals;
  std::printf(
      "frames %llu  IRs applied %llu  rays/s %.3g  segments/s %.3g  cache entries %zu (%.1f MB)\n"
      "cache budget %.1f MB (pool)  coarse entries %zu  entries merged %llu (carrying %.2f %% of "
      "the response's energy)  pool growths refused %llu\n"
      "propagation %.2f s (trace %.2f, pairs' direct sound, exact paths and caches %.2f, IR "
      "synthesis %.2f, partition+FFT %.2f)  wall %.2f s  real-time factor %.1fx\n",
      (unsigned long long)t.frames, (unsigned long long)r.listeners.front().irsApplied,
      t.traceSeconds > 0 ? t.rays / t.traceSeconds : 0.0,
      t.traceSeconds > 0 ? t.segments / t.traceSeconds : 0.0, r.last.cacheEntries,
      r.last.cacheBytes / 1e6, r.last.cacheBudgetBytes / 1e6, r.last.cacheCoarseEntries,
      (unsigned long long)r.last.cacheMergedEntries, 100.0 * r.last.cacheCoarseEnergyFraction,
      (unsigned long long)r.last.cachePoolRefusals,
      t.traceSeconds + t.pairsSeconds + t.synthesisSeconds + t.prepareSeconds, t.traceSeconds,
      t.pairsSeconds, t.synthesisSeconds, t.prepareSeconds, r.wallSeconds,
      audioSeconds / r.wallSeconds);
  std::printf(
      "energy beyond the IR length %.3g %% of the last response (largest per pair)  "
      "energy in rays ended at max_order %.3g %% of the emitted (largest band and pair)  "
      "IR sets lost %llu  convolution partitions left out after a jump %llu  diffraction "
      "chains left out %llu (last frame)\n",
      100.0 * r.last.droppedEnergyFraction, 100.0 * r.last.maxOrderEnergyFraction,
      (unsigned long long)r.irsLost,
      (unsigned long long)r.stalePartitions, (unsigned long long)r.last.chainsLeftOut);
  std::printf(
      "cache pool in use %.1f MB  per pair (%zu): smallest %.2f MB, mean %.2f MB, "
      "largest %.2f MB\n",
      r.last.cachePoolUsedBytes / 1e6, r.last.cachePairs, r.last.cachePairBytesMin / 1e6,
      r.last.cachePairs ? r.last.cacheBytes / 1e6 / double(r.last.cachePairs) : 0.0,
      r.last.cachePairBytesMax / 1e6);
  printHybrid(r.hybrid);
}

/// Progress of the wave band's simulations (scene key wave.enabled), before the render's.
void waveProgress(const SceneDesc& scene, size_t source, size_t done, size_t total) {
  if (done != total && done % (256 * 64) != 0) return;
  std::fprintf(stderr, "wave band: source %zu of %zu, step %zu / %zu\n", source + 1,
               scene.sources.size(), done, total);
}

}  // namespace

int runOffline(const Flags& fl) {
  catchStopSignals();
  const LoadedRun run = loadRun(fl, prepareOffline);
  SceneDesc& scene = *run.scene;
  OfflineOptions opt;
  opt.durationSeconds = fl.duration.value_or(-1.0);
  opt.listener = selectedListener(scene, fl);
  opt.bake = run.bake;
  checkSetup(scene, run.settings, offlineDurationSeconds(scene, run.settings, *run.dry, opt), true);
  const std::vector<OutputPaths> paths = offlineOutputs(scene, fl);
  // Several listeners: one propagation run traces them all (one pass per source and frame).
  opt.allListeners = paths.size() > 1;
  if (!fl.quiet) opt.progress = progressBar;
  opt.waveProgress = [&scene, quiet = fl.quiet](size_t s, size_t done, size_t total) {
    throwIfStopped();  // between grid steps: the wave band can take minutes
    if (!quiet) waveProgress(scene, s, done, total);
  };
  throwIfStopped();
  Writers writers = openWriters(scene, paths);
  // --gain-db is applied as the blocks are written; a stop signal ends the render here.
  const float fixedGain = fl.gainDb ? float(std::pow(10.0, *fl.gainDb / 20.0)) : 1.f;
  opt.sink = [&](size_t l, const float* const* planar, size_t frames) {
    throwIfStopped();
    writers.at(l)->write(planar, frames, fixedGain);
  };
  const OfflineResult r = renderOffline(run.scene, run.settings, run.dry, opt);
  const double audioSeconds = double(writers.front()->frames()) / scene.audio.sampleRate;
  OutputSet outputs;
  std::vector<StagedListener> staged;
  const bool signalsSilent = allSignalsSilent(scene, *run.dry);
  const float loudestDry = loudestSignalPeak(*run.dry);
  for (size_t l = 0; l < r.listeners.size() && l < paths.size(); ++l)
    staged.push_back(stageListener(fl, scene, r.listeners[l], *writers[l], paths[l], outputs,
                                   signalsSilent, loudestDry));
  throwIfStopped();
  outputs.commitAll();
  for (size_t l = 0; l < staged.size(); ++l)
    printWritten(scene, r.listeners[l], staged[l], paths[l]);
  printTotals(r, audioSeconds);
  warnMaxOrder(fl.scene, run.settings.maxOrder, r.last.maxOrderEnergyFraction, false);
  if (run.bake) printBakeSummary(*run.bake, r.bake);
  std::fflush(stdout);
  if (fl.studio) serveOfflineStudio(run, fl);
  return 0;
}

}  // namespace dpc::demo
