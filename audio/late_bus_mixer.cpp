#include "audio/late_bus_mixer.h"

#include <algorithm>
#include <stdexcept>

namespace dpc::audio {

LateBusMixer::LateBusMixer(int sources, int buses, int blockSize) : blockSize_(blockSize) {
  if (sources < 1 || buses < 1 || blockSize < 1)
    throw std::invalid_argument("LateBusMixer: sources, buses and block size must be >= 1");
  current_.assign(size_t(sources), Voice{});
  fading_.assign(size_t(sources), Voice{});
  bus_.assign(size_t(buses) * size_t(blockSize), 0.f);
  for (int k = 0; k < buses; ++k) busPtrs_.push_back(bus_.data() + size_t(k) * size_t(blockSize));
}

void LateBusMixer::setTargets(std::span<const int> bus, std::span<const float> gain) {
  const size_t n = std::min({current_.size(), bus.size(), gain.size()});
  for (size_t s = 0; s < n; ++s) {
    const int b = bus[s] >= 0 && bus[s] < buses() ? bus[s] : -1;
    Voice& v = current_[s];
    if (b != v.bus) {
      // Leave the old bus over the next block, enter the new one from silence.
      if (v.bus >= 0) fading_[s] = Voice{v.bus, v.gain, 0.f};
      v = Voice{b, 0.f, b >= 0 ? gain[s] : 0.f};
    } else {
      v.target = gain[s];
    }
  }
}

void LateBusMixer::addRamped(Voice& v, const float* x) {
  if (v.bus < 0) return;
  float* y = busPtrs_[size_t(v.bus)];
  const float step = (v.target - v.gain) / float(blockSize_);
  float g = v.gain;
  for (int i = 0; i < blockSize_; ++i) {
    g += step;
    y[i] += g * x[i];
  }
  v.gain = v.target;
}

void LateBusMixer::mix(const float* const* in) {
  std::fill(bus_.begin(), bus_.end(), 0.f);
  for (size_t s = 0; s < current_.size(); ++s) {
    addRamped(current_[s], in[s]);
    Voice& f = fading_[s];
    if (f.bus < 0) continue;
    addRamped(f, in[s]);
    f.bus = -1;
  }
}

}  // namespace dpc::audio
