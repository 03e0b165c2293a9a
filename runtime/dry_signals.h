// DrySignals: every source's dry signal at the scene's sample rate, read from the scene's WAV
// files (or given by a host), shared read-only by the audio stages that play them.
#pragma once

#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include "scene/scene.h"

namespace dpc {

/// Dry source signals at the output rate, mono, gain applied.
struct DrySignals {
  std::vector<std::vector<float>> samples;  ///< per source, at the scene's sample rate
  std::vector<char> loop;                   ///< per source: repeat the signal (SourceDesc::loop)
  /// Per source: the linear gain of its gain_db, already applied to `samples`; host inputs
  /// (AudioStage::process with inputs) get it as they arrive. Empty: 1 for every source.
  std::vector<float> gain;
  std::vector<std::string> notes;  ///< e.g. "resampled 22050 -> 48000 Hz"
  /// Frames of the longest non-looping signal (of the longest signal if all loop). Any thread.
  size_t longestFrames() const;
};

/// The linear gain of `db` decibels (amplitude: 10^(db/20)), as a source's gain_db scales its
/// signal. Any thread.
inline float gainOfDb(double db) {
  return float(std::pow(10.0, db / 20.0));
}

/// Reads every source's signal (mixed to mono, resampled to scene.audio.sampleRate, gain
/// applied; a source without a signal gets an empty one). Control thread; allocates; throws
/// InputError naming the scene file and sources[i].signal.
DrySignals loadDrySignals(const SceneDesc& scene);

/// Memory loadDrySignals(scene) will hold, bytes, from the files' headers: every source's
/// signal as float at the scene's rate, plus the largest file read whole (all its channels,
/// before mixing and resampling). A file that cannot be read counts 0 (loadDrySignals then
/// names it). Control thread; reads the headers only.
double drySignalBytes(const SceneDesc& scene);

}  // namespace dpc
