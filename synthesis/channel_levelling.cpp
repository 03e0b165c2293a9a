#include "synthesis/channel_levelling.h"

#include <algorithm>

namespace dpc {

ChannelLevelling::ChannelLevelling(int sampleRate, size_t length, int firstBand, int lastBand)
    : sampleRate_(sampleRate),
      length_(length),
      firstBand_(firstBand),
      lastBand_(lastBand) {
  setWorkers(1, {});
}

ChannelLevelling::~ChannelLevelling() = default;

void ChannelLevelling::setWorkers(size_t workers, ParallelFor parallel) {
  while (workers_.size() < std::max<size_t>(workers, 1))
    workers_.push_back(
        {std::make_unique<WindowLeveller>(sampleRate_, length_, firstBand_, lastBand_), {}});
  workers_.resize(std::max<size_t>(workers, 1));
  parallel_ = std::move(parallel);
}

void ChannelLevelling::channelTarget(const DirectionalEnergyResponse& energy, size_t count,
                                     const std::vector<std::vector<Bands>>& weight,
                                     float omniGain, int directionalFrom, size_t c,
                                     EnergyResponse& target) {
  const EnergyResponse& first = energy.response(0);
  if (target.binCount() != first.binCount() || target.binSeconds() != first.binSeconds())
    target = EnergyResponse(double(first.binCount()) * first.binSeconds(), first.binSeconds());
  target.clear();
  std::vector<Bands>& out = target.bins();
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
                             std::span<float* const> channels,
                             std::span<const float* const> fixed) {
  if (count == 0) return;
  const size_t workers = parallel_ ? workers_.size() : 1;
  const auto group = [&](size_t g) {
    Worker& w = workers_[g];
    for (size_t c = g; c < channels.size(); c += workers) {
      channelTarget(energy, count, weight, omniGain[c], directionalFrom, c, w.target);
      w.leveller->level(w.target, onset, channels[c], fixed.empty() ? nullptr : fixed[c]);
    }
  };
  if (workers > 1)
    parallel_(workers, group);
  else
    group(0);
}

}  // namespace dpc
