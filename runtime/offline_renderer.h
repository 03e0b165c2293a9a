// Offline rendering: the live pipeline (PropagationStage -> AudioStage) driven by a simulated
// clock instead of an audio device. Block by block; every 1/frame_rate seconds of scene time
// the world state is evaluated from the trajectories, a propagation frame traces it (every
// scene listener in one pass, as live) and the rendered listeners' IR sets are handed to
// their audio stages, exactly as the propagation thread would hand them over live. The result
// is bit-identical for a given seed (and independent of the thread count).
// OfflineOptions::listener picks the listener rendered; with OfflineOptions::allListeners every
// scene listener is rendered, each with its own audio stage (convolvers), one output each.
// Control thread; allocates; throws InputError / std::runtime_error.
#pragma once

#include <functional>
#include <memory>
#include <string>

#include "audio/wav_io.h"
#include "runtime/render_pipeline.h"
#include "runtime/session_stats.h"
#include "scene/orientation.h"

namespace dpc {

struct OfflineOptions {
  /// < 0: the longest non-looping source or the end of the (non-looping) trajectory,
  /// whichever is later, plus the IR length.
  double durationSeconds = -1.0;
  /// Called about every 1 % of progress with (scene seconds rendered, total seconds).
  std::function<void(double, double)> progress;
  /// false: render scene.listeners[listener] only. true: render every listener of
  /// scene.listeners (OfflineResult::listeners in scene order).
  bool allListeners = false;
  /// The listener rendered without allListeners (scene.listeners index; std::out_of_range
  /// from renderOffline when there is no such listener).
  size_t listener = 0;
  /// If set, every rendered block goes here as it is made: (listener index in
  /// OfflineResult::listeners order, planar[c][i], frames), c < the output channels,
  /// i < frames; the last block is cut to the duration. OfflineListenerResult::output then
  /// stays empty, so memory does not grow with the duration (dpc-demo streams each listener to
  /// its WAV file). The pointers are valid during the call only. An exception thrown here ends
  /// the render and propagates out of renderOffline.
  std::function<void(size_t listener, const float* const* planar, size_t frames)> sink;
  /// If set, static sources are played from this bake of the scene (PropagationStage::
  /// attachBake; bake/bake_loader.h loads and checks one).
  std::shared_ptr<const BakedField> bake;
  /// With the scene's wave.enabled, the wave bands (wave/scene_wave.h) are simulated before
  /// the first frame and joined to every IR; this is called now and then meanwhile with
  /// (source, steps done, steps). May be empty.
  std::function<void(size_t source, size_t done, size_t total)> waveProgress;
};

/// What one listener heard.
struct OfflineListenerResult {
  std::string name;  ///< the listener's name
  /// 1 (mono) or 2 (stereo, binaural) channels at the scene's rate; no channels when
  /// OfflineOptions::sink took the blocks.
  audio::AudioData output;
  std::vector<ImpulseResponse> lastIrs;  ///< the last frame's, one per source
  /// [source]: the last frame's energy response, exact early specular paths included (a pair
  /// played from a bake: the bake's late response interpolated at the listener, then the paths)
  std::vector<EnergyResponse> lastEnergy;
  std::vector<DirectSound> lastDirect;  ///< [source]: the last frame's direct sound
  /// The last frame's poses (scene frame, metres): the listener's and each source's.
  glm::vec3 lastListenerPosition{0.f};
  Orientation lastListenerOrientation;
  std::vector<glm::vec3> lastSourcePositions;
  uint64_t irsApplied = 0;
};

struct OfflineResult {
  std::vector<OfflineListenerResult> listeners;  ///< one per listener rendered
  PropagationStage::Totals totals;               ///< one propagation run (shared by all listeners)
  /// The last frame's totals over every source-listener pair rendered: rays, cache sizes and
  /// merges, the coarse store's share of the response and the energy beyond the IR length.
  FrameTotals last;
  /// Frames that produced no IR set for a listener because every set was held by the audio
  /// stages; 0 unless the exchange's pool is too small.
  uint64_t irsLost = 0;
  /// Convolution partitions left out after an onset jump (AudioStage::stalePartitions).
  uint64_t stalePartitions = 0;
  double wallSeconds = 0.0;
  /// Baked playback's counts (all 0 without OfflineOptions::bake).
  BakedPlayback::Stats bake;
  /// Hybrid rendering's lengths and counts for the first rendered listener (on = false when
  /// every source rendered whole).
  HybridReport hybrid;
};

/// The render's length in seconds: options.durationSeconds when >= 0, otherwise the default
/// described at OfflineOptions::durationSeconds. Control thread; no allocation.
double offlineDurationSeconds(const SceneDesc& scene, const PropagationSettings& settings,
                              const DrySignals& dry, const OfflineOptions& options);

/// Renders the scene (shared, read only) with its dry signals (one per source). Control
/// thread; allocates; throws InputError / std::runtime_error / std::out_of_range (listener),
/// and whatever options.sink throws.
OfflineResult renderOffline(std::shared_ptr<const SceneDesc> scene,
                            const PropagationSettings& settings,
                            std::shared_ptr<const DrySignals> dry, const OfflineOptions& options);

}  // namespace dpc
