#include "engine/path_cache.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

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

void PathTracingEstimator::endFrame(const FrameGroups& frame, uint64_t raysEmitted,
                                    float speedOfSound, EnergyResponse& out,
                                    DirectionalEnergyResponse* directional) const {
  // The same expressions as DiffusePathCache::endFrame, so that tau = 0 matches bit for bit.
  const float n = float(raysEmitted);
  const double invC = 1.0 / double(speedOfSound);
  for (const FrameGroups::Group& g : frame.groups()) {
    const double delay = meanDelaySeconds(g.length, float(g.eta), invC);
    out.add(delay, g.intensity / n);
    if (directional) directional->add(delay, g.intensity / n, g.direction);
  }
}

DiffusePathCache::DiffusePathCache(DpcWeighting weighting, double tauSeconds,
                                   double framePeriodSeconds, size_t maxEntries)
    : weighting_(weighting), maxEntries_(maxEntries) {
  if (maxEntries_ == 0) throw std::invalid_argument("DiffusePathCache: maxEntries must be > 0");
  if (!(tauSeconds >= 0.0) || !(framePeriodSeconds > 0.0))
    throw std::invalid_argument("DiffusePathCache: tau must be >= 0 and frame period > 0");
  if (weighting_ == DpcWeighting::kWindow) {
    lifetime_ = uint32_t(std::max(1.0, std::round(tauSeconds / framePeriodSeconds)));
    window_.resize(lifetime_);
  } else if (weighting_ == DpcWeighting::kSeed) {
    // An entry is read out in the frame that creates it and every frame until it is tau old.
    lifetime_ = uint32_t(std::max(1.0, std::round(tauSeconds / framePeriodSeconds)));
    a_ = 1.0;
  } else {
    a_ = tauSeconds > 0.0 ? 1.0 - std::exp(-framePeriodSeconds / tauSeconds) : 1.0;
    // Read out at the frame of the last hit and M more frames, (1-a)^M <= drop fraction.
    lifetime_ =
        a_ >= 1.0 ? 1u : 1u + uint32_t(std::ceil(std::log(kEmaDropFraction) / std::log(1.0 - a_)));
  }
  raysBefore_.assign(size_t(lifetime_) + 1, 0);
  index_.max_load_factor(0.8f);
}

void DiffusePathCache::clear() {
  index_.clear();
  entries_.clear();
  frame_ = 0;
  decayPow_ = 1.0;
  raysTotal_ = 0;
  std::fill(raysBefore_.begin(), raysBefore_.end(), 0);
  for (auto& terms : window_) terms.clear();
}

size_t DiffusePathCache::bytes() const {
  // robin_map buckets hold the (key, index) pair and a 16-bit probe distance, padded.
  return entries_.capacity() * sizeof(Entry) +
         index_.bucket_count() * (sizeof(std::pair<uint64_t, uint32_t>) + sizeof(uint64_t)) +
         raysBefore_.capacity() * sizeof(uint64_t) +
         scratch_.capacity() * sizeof(std::pair<uint32_t, uint32_t>) + windowBytes();
}

size_t DiffusePathCache::windowBytes() const {
  size_t b = window_.capacity() * sizeof(std::vector<WindowTerm>);
  for (const auto& terms : window_) b += terms.capacity() * sizeof(WindowTerm);
  return b;
}

void DiffusePathCache::windowEndFrame(const FrameGroups& frame, float n, double invC,
                                      EnergyResponse& out, DirectionalEnergyResponse* directional) {
  // The slot of the frame W frames ago: subtract its terms, drop entries left without hits.
  std::vector<WindowTerm>& slot = window_[frame_ % window_.size()];
  for (const WindowTerm& t : slot) {
    auto it = index_.find(t.key);
    if (it == index_.end()) continue;  // removed by the entry cap
    const size_t i = it->second;
    Entry& e = entries_[i];
    e.eta -= t.eta;  // integer counts: exact
    if (e.eta <= 0.f) {
      removeAt(i);
      continue;
    }
    e.intensity -= t.intensity;
    e.length -= t.length;
    e.direction -= t.direction;
  }
  slot.clear();
  for (const FrameGroups::Group& g : frame.groups()) {
    bool inserted = false;
    Entry* e = findOrInsert(g.key, inserted);
    const Bands i = g.intensity / n;
    e->intensity += i;
    e->length += g.length;
    e->eta += float(g.eta);
    e->direction += g.direction;
    e->stamp = frame_;
    slot.push_back({g.key, i, g.length, float(g.eta), g.direction});
  }
  // Mean over the frames in the window so far (fewer than W at the start: still unbiased).
  const float frames = float(std::min<uint64_t>(uint64_t(frame_) + 1, window_.size()));
  for (const Entry& e : entries_) {
    const double delay = meanDelaySeconds(e.length, e.eta, invC);
    out.add(delay, e.intensity / frames);
    if (directional) directional->add(delay, e.intensity / frames, e.direction);
  }
}

DiffusePathCache::Entry* DiffusePathCache::findOrInsert(uint64_t key, bool& inserted) {
  auto [it, ins] = index_.try_emplace(key, uint32_t(entries_.size()));
  inserted = ins;
  if (ins) entries_.push_back(Entry{key, frame_, 0.f, Bands(0.f), 0.f, glm::vec3(0.f)});
  return &entries_[it->second];
}

void DiffusePathCache::removeAt(size_t i) {
  index_.erase(entries_[i].key);
  if (i + 1 != entries_.size()) {
    entries_[i] = entries_.back();
    index_[entries_[i].key] = uint32_t(i);
  }
  entries_.pop_back();
}

void DiffusePathCache::endFrame(const FrameGroups& frame, uint64_t raysEmitted, float speedOfSound,
                                EnergyResponse& out, DirectionalEnergyResponse* directional) {
  const float n = float(raysEmitted);
  const double invC = 1.0 / double(speedOfSound);
  raysBefore_[frame_ % raysBefore_.size()] = raysTotal_;
  raysTotal_ += raysEmitted;
  if (weighting_ == DpcWeighting::kWindow) {
    windowEndFrame(frame, n, invC, out, directional);
  } else if (weighting_ == DpcWeighting::kSeed) {
    // Eq. 3.4, applied to the frame's hits of each path at once (the same sums).
    for (const FrameGroups::Group& g : frame.groups()) {
      bool inserted = false;
      Entry* e = findOrInsert(g.key, inserted);
      if (inserted) {
        e->eta = float(g.eta);
        e->intensity = g.intensity;
        e->length = g.length;
        e->direction = g.direction;
      } else {
        e->eta += float(g.eta);
        e->intensity += g.intensity;
        e->length += g.length;
        e->direction += g.direction;
      }
    }
    for (const Entry& e : entries_) {
      // mu: rays emitted from the frame that created the entry through this one.
      const uint64_t mu = raysTotal_ - raysBefore_[e.stamp % raysBefore_.size()];
      const double delay = meanDelaySeconds(e.length, e.eta, invC);  // eq. 3.3
      out.add(delay, e.intensity / float(mu));                       // eq. 3.2
      if (directional) directional->add(delay, e.intensity / float(mu), e.direction);
    }
    for (size_t i = entries_.size(); i-- > 0;)
      if (frame_ - entries_[i].stamp + 1 >= lifetime_) removeAt(i);
  } else {
    const float keep = float(1.0 - a_), af = float(a_);
    for (Entry& e : entries_) {
      e.intensity *= keep;
      e.length *= keep;
      e.eta *= keep;
      e.direction *= keep;
    }
    for (const FrameGroups::Group& g : frame.groups()) {
      bool inserted = false;
      Entry* e = findOrInsert(g.key, inserted);
      e->intensity += (g.intensity / n) * af;
      e->length += g.length * af;
      e->eta += float(g.eta) * af;
      e->direction += g.direction * af;
      e->stamp = frame_;
    }
    decayPow_ *= 1.0 - a_;
    const float norm = float(1.0 - decayPow_);
    for (const Entry& e : entries_) {
      const double delay = meanDelaySeconds(e.length, e.eta, invC);
      out.add(delay, e.intensity / norm);
      if (directional) directional->add(delay, e.intensity / norm, e.direction);
    }
    for (size_t i = entries_.size(); i-- > 0;)
      if (frame_ - entries_[i].stamp + 1 >= lifetime_) removeAt(i);
  }
  if (entries_.size() > maxEntries_) {
    // Memory guard: remove the oldest entries (smallest stamp) beyond the cap.
    scratch_.clear();
    for (size_t i = 0; i < entries_.size(); ++i)
      scratch_.push_back({entries_[i].stamp, uint32_t(i)});
    const size_t excess = entries_.size() - maxEntries_;
    std::nth_element(scratch_.begin(), scratch_.begin() + long(excess), scratch_.end());
    std::vector<uint64_t>& keys = dropKeys_;
    keys.clear();
    for (size_t i = 0; i < excess; ++i) keys.push_back(entries_[scratch_[i].second].key);
    for (uint64_t k : keys) removeAt(index_.find(k)->second);
    capped_ += excess;
  }
  ++frame_;
}

}  // namespace dpc
