#include "synthesis/channel_levelling.h"

#include <algorithm>
#include <stdexcept>

namespace dpc {

ChannelLevelling::ChannelLevelling(int sampleRate, size_t length, int firstBand,
                                   std::vector<int> lastBand)
    : sampleRate_(sampleRate),
      length_(length),
      firstBand_(firstBand),
      lastBand_(std::move(lastBand)) {
  if (lastBand_.empty()) throw std::invalid_argument("ChannelLevelling: no channel's bands");
  for (int b : lastBand_)
    if (std::find(bands_.begin(), bands_.end(), b) == bands_.end()) bands_.push_back(b);
  setWorkers(1, {});
}

ChannelLevelling::~ChannelLevelling() = default;

size_t ChannelLevelling::levellerOf(size_t c) const {
  return size_t(std::find(bands_.begin(), bands_.end(), lastBand_[c]) - bands_.begin());
}

void ChannelLevelling::setWorkers(size_t workers, ParallelFor parallel) {
  // Without a way to run them, level() levels every channel on worker 0: one worker then.
  const size_t n = parallel ? std::max<size_t>(workers, 1) : 1;
  workers_.resize(n);
  // Worker g levels channels g, g + n, ...: it holds a leveller for their last bands only (an
  // Ambisonic IR's W alone reaches 4 kHz, and only its worker needs that leveller).
  for (size_t g = 0; g < n; ++g) {
    std::vector<std::unique_ptr<WindowLeveller>>& own = workers_[g].levellers;
    own.resize(bands_.size());
    std::vector<bool> used(bands_.size(), false);
    for (size_t c = g; c < lastBand_.size(); c += n) used[levellerOf(c)] = true;
    for (size_t k = 0; k < bands_.size(); ++k)
      if (!used[k])
        own[k].reset();
      else if (!own[k])
        own[k] = std::make_unique<WindowLeveller>(sampleRate_, length_, firstBand_, bands_[k]);
  }
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
    for (size_t c = g; c < std::min(channels.size(), lastBand_.size()); c += workers) {
      channelTarget(energy, count, weight, omniGain[c], directionalFrom, c, w.target);
      w.levellers[levellerOf(c)]->level(w.target, onset, channels[c],
                                        fixed.empty() ? nullptr : fixed[c]);
    }
  };
  if (workers > 1)
    parallel_(workers, group);
  else
    group(0);
}

}  // namespace dpc
