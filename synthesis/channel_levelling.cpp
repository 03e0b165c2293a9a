#include "synthesis/channel_levelling.h"

#include <algorithm>

namespace dpc {

ChannelLevelling::ChannelLevelling(int sampleRate, size_t length, size_t startSample,
                                   int firstBand, int lastBand)
    : leveller_(sampleRate, length, firstBand, lastBand), start_(startSample) {}

void ChannelLevelling::channelTarget(const DirectionalEnergyResponse& energy, size_t count,
                                     const std::vector<std::vector<Bands>>& weight,
                                     float omniGain, int directionalFrom, size_t c) {
  const EnergyResponse& first = energy.response(0);
  if (target_.binCount() != first.binCount() || target_.binSeconds() != first.binSeconds())
    target_ = EnergyResponse(double(first.binCount()) * first.binSeconds(), first.binSeconds());
  target_.clear();
  std::vector<Bands>& out = target_.bins();
  const float omni2 = omniGain * omniGain;
  for (size_t d = 0; d < count; ++d) {
    const std::vector<Bands>& in = energy.response(d).bins();
    const Bands& w = weight[d][c];
    for (size_t k = 0; k < out.size() && k < in.size(); ++k)
      for (int b = 0; b < kNumBands; ++b)
        out[k][b] += (b < directionalFrom ? omni2 : w[b]) * std::max(0.f, in[k][b]);
  }
}

void ChannelLevelling::level(const DirectionalEnergyResponse& energy, size_t count,
                             const std::vector<std::vector<Bands>>& weight,
                             std::span<const float> omniGain, int directionalFrom, size_t onset,
                             std::span<float* const> channels) {
  if (count == 0) return;
  for (size_t c = 0; c < channels.size(); ++c) {
    channelTarget(energy, count, weight, omniGain[c], directionalFrom, c);
    leveller_.level(target_, onset, start_, channels[c]);
  }
}

}  // namespace dpc
