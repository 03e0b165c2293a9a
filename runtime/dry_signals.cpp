#include "runtime/dry_signals.h"

#include <algorithm>
#include <cmath>

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

DrySignals loadDrySignals(const SceneDesc& scene) {
  DrySignals d;
  for (size_t i = 0; i < scene.sources.size(); ++i) {
    const SourceDesc& src = scene.sources[i];
    const std::string field = "sources[" + std::to_string(i) + "].signal";
    if (src.signalPath.empty()) {  // host input only: silence when played on its own
      d.samples.emplace_back();
      d.loop.push_back(0);
      d.notes.push_back("sources[" + std::to_string(i) + "]: no signal (silent without host input)");
      continue;
    }
    audio::AudioData a;
    try {
      a = audio::readWav(src.signalPath);
    } catch (const InputError& e) {
      throw InputError(scene.path, field, e.what());
    }
    if (a.frames() == 0) throw InputError(scene.path, field, src.signalPath + ": no samples");
    if (a.sampleRate < kMinSignalRateHz || a.sampleRate > kMaxSignalRateHz)
      throw InputError(scene.path, field,
                       src.signalPath + ": sample rate " + std::to_string(a.sampleRate) +
                           " Hz is outside [" + std::to_string(kMinSignalRateHz) + ", " +
                           std::to_string(kMaxSignalRateHz) + "] Hz");
    for (size_t c = 0; c < a.channels.size(); ++c)
      for (size_t n = 0; n < a.frames(); ++n)
        if (!std::isfinite(a.channels[c][n]))
          throw InputError(scene.path, field,
                           src.signalPath + ": sample " + std::to_string(n) + " of channel " +
                               std::to_string(c) + " is not finite (NaN or infinity)");
    if (a.channels.size() > 1) {
      std::vector<float> mono(a.frames(), 0.f);
      for (const auto& ch : a.channels)
        for (size_t n = 0; n < mono.size(); ++n) mono[n] += ch[n] / float(a.channels.size());
      d.notes.push_back(src.signalPath + ": " + std::to_string(a.channels.size()) +
                        " channels mixed to mono");
      a.channels = {std::move(mono)};
    }
    if (a.sampleRate != scene.audio.sampleRate) {
      d.notes.push_back(src.signalPath + ": resampled " + std::to_string(a.sampleRate) + " -> " +
                        std::to_string(scene.audio.sampleRate) + " Hz");
      a = audio::resample(a, scene.audio.sampleRate);
    }
    const float gain = float(std::pow(10.0, src.gainDb / 20.0));
    for (float& x : a.channels[0]) x *= gain;
    d.samples.push_back(std::move(a.channels[0]));
    d.loop.push_back(src.loop ? 1 : 0);
  }
  return d;
}

}  // namespace dpc
