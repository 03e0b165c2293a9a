#include "wave/wave_join.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "common/butterworth.h"

namespace dpc::wave {

double waveBandGain(OutputFormat format, int channel, int channels) {
  switch (format) {
    case OutputFormat::kMono:
    case OutputFormat::kBinaural:
    case OutputFormat::kAmbisonicBinaural:
      return 1.0;
    case OutputFormat::kAmbisonics:
      return channel == 0 ? 1.0 : 0.0;
    case OutputFormat::kStereo:
    case OutputFormat::kLoudspeakers:
      return 1.0 / std::sqrt(double(std::max(channels, 1)));
  }
  return 0.0;
}

void joinWaveBand(std::span<float> rayChannel, std::span<const float> wave, double gain,
                  double crossoverHz, double fs) {
  using K = Butterworth::Kind;
  Butterworth::design(K::kHighPass, kCrossoverOrder, crossoverHz, fs).run(rayChannel);
  if (gain == 0.0) return;
  std::vector<float> low(rayChannel.size(), 0.f);
  std::copy_n(wave.begin(), std::min(wave.size(), low.size()), low.begin());
  Butterworth::design(K::kLowPass, kCrossoverOrder, crossoverHz, fs).run(low);
  for (size_t i = 0; i < low.size(); ++i) rayChannel[i] += float(gain * double(low[i]));
}

}  // namespace dpc::wave
