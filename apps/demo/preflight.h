// Checks dpc-demo makes before any work, shared by the live and the offline run.
#pragma once

#include <memory>
#include <vector>

#include "apps/demo/flags.h"
#include "common/input_error.h"
#include "runtime/offline_renderer.h"
#include "scene/scene.h"

namespace dpc::demo {

/// Longest render or live run accepted, seconds (a day).
constexpr double kMaxDurationSeconds = 86400.0;

/// Prints the scene's load warnings, one "warning: ..." line each on stderr. Main thread.
void printSceneWarnings(const SceneDesc& scene);

/// Throws InputError for a --duration outside (0, kMaxDurationSeconds]. Main thread.
void checkDuration(const Flags& fl);

/// A scene whose sources have no signal is for hosts that feed them (C API, LV2 plugin);
/// dpc-demo would only render silence. Throws InputError naming sources[0].signal. Main thread.
void requireSignal(const SceneDesc& scene);

/// Refuses a render that cannot finish or fit (engine/workload.h) and prints one-line warnings
/// for heavy work and for setups that cannot be meant (engine/setup_check.h), if `warn`.
/// durationSeconds <= 0: not known yet (before the dry signals are loaded; live), only the
/// per-frame and memory checks apply. Main thread. Throws InputError.
void checkSetup(const SceneDesc& scene, const PropagationSettings& settings, double durationSeconds,
                bool warn);

/// A peak below this (-600 dBFS) is silence: a dry signal that quiet gets a warning naming it,
/// and an offline render that quiet is not normalised (a gain to -1 dBFS would overflow float).
constexpr float kSilentPeak = 1e-30f;

/// An offline render peaking this far below its loudest dry signal (-160 dB) holds float
/// rounding, not sound (a render that ends before any sound arrives): it is not normalised
/// (+400 dB would make its rounding full scale) and is warned about. Spreading over 10 km
/// (-91 dB) and a 40 dB partition stay well above it.
constexpr double kRoundingPeakRatio = 1e-8;

/// The largest absolute sample over every dry signal (0 for none). Any thread; no allocation.
float loudestSignalPeak(const DrySignals& dry);

/// The sources (scene.sources indices) that have a signal whose peak is below kSilentPeak.
/// Any thread; no allocation beyond the result.
std::vector<size_t> silentSignals(const SceneDesc& scene, const DrySignals& dry);

/// True if every source with a signal is in silentSignals: a silent render is then the
/// signals', not the geometry's.
bool allSignalsSilent(const SceneDesc& scene, const DrySignals& dry);

/// The scene's dry signals (shared with the renderer or the session), with one "note: ..."
/// line on stderr per note of the loader and one "warning: ..." line per silent signal
/// (silentSignals). Main thread. Allocates; throws InputError for a signal that cannot be read.
std::shared_ptr<const DrySignals> loadDrySignalsWithNotes(const SceneDesc& scene);

/// What a live or offline run starts from: the scene (after --flag overrides), its settings
/// and its dry signals.
struct LoadedRun {
  std::shared_ptr<SceneDesc> scene;
  PropagationSettings settings;
  std::shared_ptr<const DrySignals> dry;
  std::shared_ptr<const BakedField> bake;  ///< --bake, loaded and checked; or none
};

/// A problem with the scene file's own value, found as it loaded: blamed on the file's field
/// even where a flag overrides that field (the flag's value is checked apart).
struct SceneFileError : InputError {
  explicit SceneFileError(const InputError& e) : InputError(e) {}
};

/// Loads fl.scene (its errors as SceneFileError), applies `prepare` (the mode's overrides and
/// checks, which may change the scene and return its settings), loads --bake for it
/// (bake_flag.h), then loads the dry signals with their notes. Main thread.
/// Allocates; throws InputError.
LoadedRun loadRun(const Flags& fl, PropagationSettings (*prepare)(SceneDesc&, const Flags&));

}  // namespace dpc::demo
