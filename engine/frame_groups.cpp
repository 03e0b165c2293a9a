#include "engine/frame_groups.h"

namespace dpc {

void FrameGroups::clear() {
  index_.clear();
  groups_.clear();
  hits_ = 0;
}

void FrameGroups::add(const PathHit& hit) {
  ++hits_;
  const float w = hit.intensity.average();
  auto [it, inserted] = index_.try_emplace(hit.key, uint32_t(groups_.size()));
  if (inserted) {
    groups_.push_back({hit.key, 1u, hit.intensity, hit.length, hit.direction * w});
    return;
  }
  Group& g = groups_[it->second];
  g.eta += 1;
  g.intensity += hit.intensity;
  g.length += hit.length;
  g.direction += hit.direction * w;
}

}  // namespace dpc
