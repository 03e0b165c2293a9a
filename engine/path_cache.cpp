#include "engine/path_cache.h"

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
    groups_.push_back({hit.key, 1u, hit.intensity, double(hit.length), hit.direction * w});
    return;
  }
  Group& g = groups_[it->second];
  g.eta += 1;
  g.intensity += hit.intensity;
  g.length += double(hit.length);
  g.direction += hit.direction * w;
}

void PathTracingEstimator::endFrame(const FrameGroups& frame, uint64_t raysEmitted,
                                    float speedOfSound, EnergyResponse& out) const {
  // The same expressions as DiffusePathCache::endFrame, so that tau = 0 matches bit for bit.
  const float n = float(raysEmitted);
  const double invC = 1.0 / double(speedOfSound);
  for (const FrameGroups::Group& g : frame.groups()) {
    const double rBar = g.length / double(g.eta);
    out.add(rBar * invC, g.intensity / n);
  }
}

DiffusePathCache::DiffusePathCache(DpcWeighting weighting, double tauSeconds,
                                   double framePeriodSeconds)
    : weighting_(weighting) {
  if (!(tauSeconds >= 0.0) || !(framePeriodSeconds > 0.0))
    throw std::invalid_argument("DiffusePathCache: tau must be >= 0 and frame period > 0");
  if (weighting_ == DpcWeighting::kSeed) {
    // An entry is read out in the frame that creates it and every frame until it is tau old.
    lifetime_ = uint32_t(std::max(1.0, std::round(tauSeconds / framePeriodSeconds)));
    a_ = 1.0;
  } else {
    a_ = tauSeconds > 0.0 ? 1.0 - std::exp(-framePeriodSeconds / tauSeconds) : 1.0;
    // Read out at the frame of the last hit and M more frames, (1-a)^M <= drop fraction.
    lifetime_ = a_ >= 1.0 ? 1u
                          : 1u + uint32_t(std::ceil(std::log(kEmaDropFraction) /
                                                    std::log(1.0 - a_)));
  }
}

void DiffusePathCache::clear() {
  index_.clear();
  entries_.clear();
  frame_ = 0;
  decayPow_ = 1.0;
}

size_t DiffusePathCache::bytes() const {
  return entries_.capacity() * sizeof(Entry) +
         index_.bucket_count() * (sizeof(std::pair<uint64_t, uint32_t>) + sizeof(uint32_t));
}

DiffusePathCache::Entry* DiffusePathCache::findOrInsert(uint64_t key, bool& inserted) {
  auto [it, ins] = index_.try_emplace(key, uint32_t(entries_.size()));
  inserted = ins;
  if (ins) entries_.push_back(Entry{key, 0u, frame_, 0u, Bands(0.f), 0.0, 0.0, glm::vec3(0.f)});
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

void DiffusePathCache::endFrame(const FrameGroups& frame, uint64_t raysEmitted,
                                float speedOfSound, EnergyResponse& out) {
  const float n = float(raysEmitted);
  const double invC = 1.0 / double(speedOfSound);
  if (weighting_ == DpcWeighting::kSeed) {
    // Eq. 3.4, applied to the frame's hits of each path at once (the same sums).
    for (const FrameGroups::Group& g : frame.groups()) {
      bool inserted = false;
      Entry* e = findOrInsert(g.key, inserted);
      if (inserted) {
        e->eta = g.eta;
        e->intensity = g.intensity;
        e->length = g.length;
        e->direction = g.direction;
      } else {
        e->eta += g.eta;
        e->intensity += g.intensity;
        e->length += g.length;
        e->direction += g.direction;
      }
    }
    for (Entry& e : entries_) {
      e.mu += raysEmitted;
      const double rBar = e.length / double(e.eta);                   // eq. 3.3
      out.add(rBar * invC, e.intensity / float(e.mu));                // eq. 3.2
    }
    for (size_t i = entries_.size(); i-- > 0;)
      if (frame_ - entries_[i].stamp + 1 >= lifetime_) removeAt(i);
  } else {
    const float keep = float(1.0 - a_), af = float(a_);
    for (Entry& e : entries_) {
      e.intensity *= keep;
      e.length *= 1.0 - a_;
      e.etaAverage *= 1.0 - a_;
      e.direction *= keep;
    }
    for (const FrameGroups::Group& g : frame.groups()) {
      bool inserted = false;
      Entry* e = findOrInsert(g.key, inserted);
      e->intensity += (g.intensity / n) * af;
      e->length += g.length * a_;
      e->etaAverage += double(g.eta) * a_;
      e->direction += g.direction * af;
      e->stamp = frame_;
    }
    decayPow_ *= 1.0 - a_;
    const float norm = float(1.0 - decayPow_);
    for (const Entry& e : entries_) {
      const double rBar = e.length / e.etaAverage;
      out.add(rBar * invC, e.intensity / norm);
    }
    for (size_t i = entries_.size(); i-- > 0;)
      if (frame_ - entries_[i].stamp + 1 >= lifetime_) removeAt(i);
  }
  ++frame_;
}

}  // namespace dpc
