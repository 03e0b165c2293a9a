#include "apps/studio/surface_heat.h"

#include <algorithm>

namespace dpc::studio {

SurfaceHeat::SurfaceHeat(size_t triangles, double frames)
    : mean_(triangles, 0.f), frame_(triangles, 0.f), weight_(1.0 / std::max(1.0, frames)) {}

void SurfaceHeat::reset() {
  std::fill(mean_.begin(), mean_.end(), 0.f);
  empty_ = true;
}

void SurfaceHeat::add(std::span<const SurfaceTally::Surface> frame) {
  std::fill(frame_.begin(), frame_.end(), 0.f);
  for (const SurfaceTally::Surface& s : frame)
    if (s.triangle < frame_.size()) frame_[s.triangle] = s.intensity.average();
  const float w = empty_ ? 1.f : float(weight_);
  for (size_t t = 0; t < mean_.size(); ++t) mean_[t] += w * (frame_[t] - mean_[t]);
  empty_ = false;
}

void SurfaceHeat::nonzero(std::vector<uint32_t>& triangles, std::vector<float>& energy) const {
  triangles.clear();
  energy.clear();
  for (size_t t = 0; t < mean_.size(); ++t)
    if (mean_[t] > 0.f) {
      triangles.push_back(uint32_t(t));
      energy.push_back(mean_[t]);
    }
}

}  // namespace dpc::studio
