// dpc-demo's checks before any work: duration, signals, workload, memory.
#include "apps/demo/preflight.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "apps/demo/bake_flag.h"
#include "common/input_error.h"
#include "engine/setup_check.h"
#include "engine/workload.h"
#include "runtime/output_format.h"

namespace dpc::demo {
namespace {

/// The largest absolute sample of one signal (0 for none).
float signalPeak(const std::vector<float>& signal) {
  float peak = 0.f;
  for (const float x : signal) peak = std::max(peak, std::abs(x));
  return peak;
}

}  // namespace

void printSceneWarnings(const SceneDesc& scene) {
  for (const std::string& w : scene.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
}

void checkDuration(const Flags& fl) {
  if (fl.duration && !(*fl.duration > 0.0 && *fl.duration <= kMaxDurationSeconds))
    throw InputError("command line", "--duration",
                     "must be in (0, " + std::to_string(int(kMaxDurationSeconds)) + "] seconds");
}

void requireSignal(const SceneDesc& scene) {
  for (const SourceDesc& s : scene.sources)
    if (!s.signalPath.empty()) return;
  throw InputError(scene.path, "sources[0].signal",
                   "no source has a signal: nothing to play (signal-less scenes are for the C "
                   "API and the LV2 plugin, which feed the sources)");
}

void checkSetup(const SceneDesc& scene, const PropagationSettings& settings, double durationSeconds,
                bool warn) {
  WorkloadEstimate e =
      estimateWorkload(scene, settings, irChannels(scene.audio), durationSeconds);
  e.signalBytes = drySignalBytes(scene);
  const std::vector<std::string> heavy = checkWorkload(scene, settings, e, plannableMemoryBytes());
  if (!warn) return;
  for (const std::string& w : heavy) std::fprintf(stderr, "warning: %s\n", w.c_str());
  for (const std::string& w : setupWarnings(scene))
    std::fprintf(stderr, "warning: %s\n", w.c_str());
}

std::vector<size_t> silentSignals(const SceneDesc& scene, const DrySignals& dry) {
  std::vector<size_t> silent;
  for (size_t s = 0; s < scene.sources.size() && s < dry.samples.size(); ++s)
    if (!scene.sources[s].signalPath.empty() && signalPeak(dry.samples[s]) < kSilentPeak)
      silent.push_back(s);
  return silent;
}

float loudestSignalPeak(const DrySignals& dry) {
  float peak = 0.f;
  for (const std::vector<float>& signal : dry.samples) peak = std::max(peak, signalPeak(signal));
  return peak;
}

bool allSignalsSilent(const SceneDesc& scene, const DrySignals& dry) {
  const size_t withSignal =
      size_t(std::count_if(scene.sources.begin(), scene.sources.end(),
                           [](const SourceDesc& s) { return !s.signalPath.empty(); }));
  return silentSignals(scene, dry).size() == withSignal;
}

std::shared_ptr<const DrySignals> loadDrySignalsWithNotes(const SceneDesc& scene) {
  auto dry = std::make_shared<const DrySignals>(loadDrySignals(scene));
  for (const std::string& n : dry->notes) std::fprintf(stderr, "note: %s\n", n.c_str());
  for (const size_t s : silentSignals(scene, *dry))
    std::fprintf(stderr,
                 "warning: %s: sources[%zu].signal: '%s' is silent (its peak after gain_db is below "
                 "%g, %.0f dBFS): source '%s' plays nothing\n",
                 scene.path.c_str(), s, scene.sources[s].signalPath.c_str(), double(kSilentPeak),
                 20.0 * std::log10(double(kSilentPeak)), scene.sources[s].name.c_str());
  return dry;
}

LoadedRun loadRun(const Flags& fl, PropagationSettings (*prepare)(SceneDesc&, const Flags&)) {
  LoadedRun run;
  try {
    run.scene = std::make_shared<SceneDesc>(loadScene(fl.scene));
  } catch (const InputError& e) {
    throw SceneFileError(e);
  }
  run.settings = prepare(*run.scene, fl);
  run.bake = loadBakeFlag(fl, *run.scene, run.settings);
  run.dry = loadDrySignalsWithNotes(*run.scene);
  return run;
}

}  // namespace dpc::demo
