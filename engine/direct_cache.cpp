#include "engine/direct_cache.h"

#include <algorithm>

namespace dpc {

namespace {
bool samePose(const Pose& a, const Pose& b) {
  return a.position == b.position && a.rotation == b.rotation;
}
}  // namespace

void DirectCache::posesApplied(const std::vector<Pose>& poses) {
  if (poses.size() == poses_.size() && std::equal(poses.begin(), poses.end(), poses_.begin(), samePose))
    return;
  poses_ = poses;  // allocates only when the object count grows
  ++geometry_;
}

bool DirectCache::holds(size_t pair, const glm::vec3& source, const glm::vec3& forward,
                        const ListenerSphere& listener) const {
  if (pair >= entries_.size()) return false;
  const Entry& e = entries_[pair];
  return e.valid && e.geometry == geometry_ && e.source == source && e.forward == forward &&
         e.listener == listener.position && e.radius == listener.radius;
}

void DirectCache::computed(size_t pair, const glm::vec3& source, const glm::vec3& forward,
                           const ListenerSphere& listener) {
  if (pair >= entries_.size()) return;
  entries_[pair] = Entry{source, forward, listener.position, listener.radius, geometry_, true};
}

}  // namespace dpc
