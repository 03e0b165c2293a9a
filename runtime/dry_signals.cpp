#include "runtime/dry_signals.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "audio/resample.h"
#include "audio/wav_io.h"
#include "common/input_error.h"
#include "common/input_file.h"

namespace dpc {

size_t DrySignals::longestFrames() const {
  size_t once = 0, any = 0;
  for (size_t i = 0; i < samples.size(); ++i) {
    any = std::max(any, samples[i].size());
    if (!loop[i]) once = std::max(once, samples[i].size());
  }
  return once > 0 ? once : any;
}

namespace {

/// Reads source i's WAV file; throws InputError naming sources[i].signal when it cannot be
/// read, is empty, has a rate outside [kMinSignalRateHz, kMaxSignalRateHz] or a sample that
/// is not finite.
audio::AudioData readSignal(const SceneDesc& scene, size_t i) {
  const std::string& path = scene.sources[i].signalPath;
  const std::string field = "sources[" + std::to_string(i) + "].signal";
  audio::AudioData a;
  try {
    a = audio::readWav(path);
  } catch (const InputError& e) {
    throw InputError(scene.path, field, e.what());
  }
  if (a.frames() == 0) throw InputError(scene.path, field, path + ": no samples");
  if (a.sampleRate < kMinSignalRateHz || a.sampleRate > kMaxSignalRateHz)
    throw InputError(scene.path, field,
                     path + ": sample rate " + std::to_string(a.sampleRate) + " Hz is outside [" +
                         std::to_string(kMinSignalRateHz) + ", " +
                         std::to_string(kMaxSignalRateHz) + "] Hz");
  for (size_t c = 0; c < a.channels.size(); ++c)
    for (size_t n = 0; n < a.frames(); ++n)
      if (const std::string why = sampleProblem(a.channels[c][n]); !why.empty())
        throw InputError(scene.path, field,
                         path + ": sample " + std::to_string(n) + " (0 = first) of channel " +
                             std::to_string(c + 1) + " " + why);
  return a;
}

/// One mono channel at `rate` Hz: channels averaged, then resampled; notes say what was done.
std::vector<float> monoAtRate(audio::AudioData a, int rate, const std::string& path,
                              std::vector<std::string>& notes) {
  if (a.channels.size() > 1) {
    std::vector<float> mono(a.frames(), 0.f);
    for (const auto& ch : a.channels)
      for (size_t n = 0; n < mono.size(); ++n) mono[n] += ch[n] / float(a.channels.size());
    notes.push_back(path + ": " + std::to_string(a.channels.size()) + " channels mixed to mono");
    a.channels = {std::move(mono)};
  }
  if (a.sampleRate != rate) {
    notes.push_back(path + ": resampled " + std::to_string(a.sampleRate) + " -> " +
                    std::to_string(rate) + " Hz");
    a = audio::resample(a, rate);
  }
  return std::move(a.channels[0]);
}

}  // namespace

double drySignalBytes(const SceneDesc& scene) {
  double held = 0.0, largestRead = 0.0;
  for (const SourceDesc& src : scene.sources) {
    if (src.signalPath.empty()) continue;
    try {
      const audio::SoundFileInfo f = audio::readSoundFileInfo(src.signalPath);
      held +=
          double(f.frames) * double(scene.audio.sampleRate) / double(f.sampleRate) * sizeof(float);
      largestRead = std::max(largestRead, double(f.frames) * f.channels * sizeof(float));
    } catch (const InputError&) {
    }
  }
  return held + largestRead;
}

DrySignals loadDrySignals(const SceneDesc& scene) {
  DrySignals d;
  // Each file is read, mixed and resampled once, however many sources play it (a crowd of
  // voices from one recording): resampling is the slow part of loading.
  // The last source playing a file takes its converted copy, so the memory held stays what
  // drySignalBytes() estimates.
  std::map<std::string, std::vector<float>> converted;
  std::map<std::string, size_t> usesLeft;
  for (const SourceDesc& src : scene.sources)
    if (!src.signalPath.empty()) ++usesLeft[src.signalPath];
  for (size_t i = 0; i < scene.sources.size(); ++i) {
    const SourceDesc& src = scene.sources[i];
    d.gain.push_back(gainOfDb(src.gainDb));
    if (src.signalPath.empty()) {  // host input only: silence when played on its own
      d.samples.emplace_back();
      d.loop.push_back(0);
      d.notes.push_back("sources[" + std::to_string(i) +
                        "]: no signal (silent without host input)");
      continue;
    }
    auto it = converted.find(src.signalPath);
    if (it == converted.end())
      it = converted
               .emplace(src.signalPath, monoAtRate(readSignal(scene, i), scene.audio.sampleRate,
                                                   src.signalPath, d.notes))
               .first;
    std::vector<float> x = --usesLeft[src.signalPath] == 0 ? std::move(it->second) : it->second;
    for (float& v : x) v *= d.gain.back();
    d.samples.push_back(std::move(x));
    d.loop.push_back(src.loop ? 1 : 0);
  }
  return d;
}

}  // namespace dpc
