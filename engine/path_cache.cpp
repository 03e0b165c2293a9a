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

size_t DiffusePathCache::entriesForBudget(double megabytes) {
  return std::max<size_t>(1, size_t(megabytes * 1048576.0) / kBytesPerEntry);
}

void DiffusePathCache::clear() {
  index_.clear();
  entries_.clear();
  coarseIndex_.clear();
  coarse_.clear();
  coarseFraction_ = 0.0;
  frame_ = 0;
  decayPow_ = 1.0;
  raysTotal_ = 0;
  std::fill(raysBefore_.begin(), raysBefore_.end(), 0);
  for (auto& terms : window_) terms.clear();
  mergedAt_.clear();
}

size_t DiffusePathCache::bytes() const {
  // robin_map buckets hold the (key, index) pair and a 16-bit probe distance, padded.
  return entries_.capacity() * sizeof(Entry) +
         index_.bucket_count() * (sizeof(std::pair<uint64_t, uint32_t>) + sizeof(uint64_t)) +
         raysBefore_.capacity() * sizeof(uint64_t) +
         scratch_.capacity() * sizeof(std::pair<uint32_t, uint32_t>) +
         coarse_.capacity() * sizeof(Entry) +
         coarseIndex_.bucket_count() * (sizeof(std::pair<uint64_t, uint32_t>) + sizeof(uint64_t)) +
         mergedAt_.bucket_count() * (sizeof(std::pair<uint64_t, MergeRecord>) + sizeof(uint64_t)) +
         windowBytes();
}

size_t DiffusePathCache::windowBytes() const {
  size_t b = window_.capacity() * sizeof(std::vector<WindowTerm>);
  for (const auto& terms : window_) b += terms.capacity() * sizeof(WindowTerm);
  return b;
}

void DiffusePathCache::removeCoarseAt(size_t i) {
  coarseIndex_.erase(coarse_[i].key);
  if (i + 1 != coarse_.size()) {
    coarse_[i] = coarse_.back();
    coarseIndex_[coarse_[i].key] = uint32_t(i);
  }
  coarse_.pop_back();
}

void DiffusePathCache::windowEndFrame(const FrameGroups& frame, float n, double invC,
                                      EnergyResponse& out, DirectionalEnergyResponse* directional,
                                      double& total, double& coarse) {
  // The slot of frame f0 = frame_ - W: subtract its terms from the entry that holds them (the
  // path entry, or the coarse entry it was merged into before or at f0), and remove entries
  // left without hits in the window. Hit counts are integers, so eta reaches 0 exactly.
  std::vector<WindowTerm>& slot = window_[frame_ % window_.size()];
  const uint64_t f0 = uint64_t(frame_) - window_.size();  // only read when the slot is filled
  auto retire = [](Entry& e, const WindowTerm& t) {
    e.eta -= t.eta;
    e.intensity -= t.intensity;
    e.length -= t.length;
    e.direction -= t.direction;
    return e.eta <= 0.5f;
  };
  for (const WindowTerm& t : slot) {
    auto m = mergedAt_.find(t.key);
    if (m != mergedAt_.end() && f0 <= m->second.frame) {
      auto c = coarseIndex_.find(m->second.coarseKey);
      if (c != coarseIndex_.end() && retire(coarse_[c->second], t)) removeCoarseAt(c->second);
      continue;
    }
    auto it = index_.find(t.key);
    if (it != index_.end() && retire(entries_[it->second], t)) removeAt(it->second);
  }
  slot.clear();
  // Terms from frames up to f0 have all left: their merge records are no longer needed.
  if (frame_ >= window_.size())
    for (auto m = mergedAt_.begin(); m != mergedAt_.end();)
      m = m->second.frame <= f0 ? mergedAt_.erase(m) : std::next(m);
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
  auto readout = [&](const Entry& e) {
    const double delay = meanDelaySeconds(e.length, e.eta, invC);
    out.add(delay, e.intensity / frames);
    if (directional) directional->add(delay, e.intensity / frames, e.direction);
    return double((e.intensity / frames).average());
  };
  for (const Entry& e : entries_) total += readout(e);
  for (const Entry& e : coarse_) coarse += readout(e);
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

void DiffusePathCache::mergeIntoCoarse(const Entry& e, double invSpeedOfSound) {
  // Seed entries merge only with entries of the same creation frame, so that mu (rays since
  // creation) and the lifetime are shared and I_hat / mu stays exactly additive. EMA entries
  // decay by the same factor whatever their age, so any two merge exactly; the coarse entry
  // expires with the newest member's last hit (the older members' remaining weight is below
  // kEmaDropFraction by then).
  // Window entries: the path's terms still in the window are later subtracted from the coarse
  // entry it went into (mergedAt_), so a path merged again goes into the same coarse entry.
  const double delay = e.eta > 0.f ? meanDelaySeconds(e.length, e.eta, invSpeedOfSound) : 0.0;
  const uint64_t bin = uint64_t(std::max(0.0, delay / kCoarseBinSeconds));
  const uint64_t stamp = weighting_ == DpcWeighting::kSeed ? uint64_t(e.stamp) + 1 : 0;
  uint64_t key = bin * 0x9E3779B97F4A7C15ull ^ (stamp << 40);
  if (weighting_ == DpcWeighting::kWindow) {
    auto [m, fresh] = mergedAt_.try_emplace(e.key, MergeRecord{key, frame_});
    if (!fresh) {
      key = m->second.coarseKey;
      m.value().frame = frame_;
    }
  }
  auto [it, ins] = coarseIndex_.try_emplace(key, uint32_t(coarse_.size()));
  if (ins) {
    coarse_.push_back(e);
    coarse_.back().key = key;
    return;
  }
  Entry& c = coarse_[it->second];
  c.eta += e.eta;
  c.intensity += e.intensity;
  c.length += e.length;
  c.direction += e.direction;
  c.stamp = std::max(c.stamp, e.stamp);
}

void DiffusePathCache::endFrame(const FrameGroups& frame, uint64_t raysEmitted, float speedOfSound,
                                EnergyResponse& out, DirectionalEnergyResponse* directional) {
  const float n = float(raysEmitted);
  const double invC = 1.0 / double(speedOfSound);
  raysBefore_[frame_ % raysBefore_.size()] = raysTotal_;
  raysTotal_ += raysEmitted;
  double total = 0.0, coarse = 0.0;  // band-average energy read out: all, from the coarse store
  if (weighting_ == DpcWeighting::kWindow) {
    windowEndFrame(frame, n, invC, out, directional, total, coarse);
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
    auto readout = [&](const Entry& e) {
      // mu: rays emitted from the frame that created the entry through this one.
      const uint64_t mu = raysTotal_ - raysBefore_[e.stamp % raysBefore_.size()];
      const double delay = meanDelaySeconds(e.length, e.eta, invC);  // eq. 3.3
      out.add(delay, e.intensity / float(mu));                       // eq. 3.2
      if (directional) directional->add(delay, e.intensity / float(mu), e.direction);
      return double((e.intensity / float(mu)).average());
    };
    for (const Entry& e : entries_) total += readout(e);
    for (const Entry& e : coarse_) coarse += readout(e);
  } else {
    const float keep = float(1.0 - a_), af = float(a_);
    for (std::vector<Entry>* store : {&entries_, &coarse_})
      for (Entry& e : *store) {
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
    auto readout = [&](const Entry& e) {
      const double delay = meanDelaySeconds(e.length, e.eta, invC);
      out.add(delay, e.intensity / norm);
      if (directional) directional->add(delay, e.intensity / norm, e.direction);
      return double((e.intensity / norm).average());
    };
    for (const Entry& e : entries_) total += readout(e);
    for (const Entry& e : coarse_) coarse += readout(e);
  }
  total += coarse;
  coarseFraction_ = total > 0.0 ? coarse / total : 0.0;
  if (weighting_ != DpcWeighting::kWindow) {  // window entries leave with their last term
    for (size_t i = entries_.size(); i-- > 0;)
      if (frame_ - entries_[i].stamp + 1 >= lifetime_) removeAt(i);
    for (size_t i = coarse_.size(); i-- > 0;)
      if (frame_ - coarse_[i].stamp + 1 >= lifetime_) removeCoarseAt(i);
  }
  if (entries_.size() + coarse_.size() > maxEntries_ && !entries_.empty()) {
    // Budget: merge the oldest path entries (smallest stamp) into the coarse store until path
    // plus coarse entries fit. Merging may create coarse entries, so repeat while over.
    scratch_.clear();
    for (size_t i = 0; i < entries_.size(); ++i)
      scratch_.push_back({entries_[i].stamp, uint32_t(i)});
    std::sort(scratch_.begin(), scratch_.end());
    std::vector<uint64_t>& keys = dropKeys_;
    keys.clear();
    for (size_t j = 0;
         j < scratch_.size() && entries_.size() - keys.size() + coarse_.size() > maxEntries_; ++j) {
      const Entry& e = entries_[scratch_[j].second];
      mergeIntoCoarse(e, invC);
      keys.push_back(e.key);
    }
    for (uint64_t k : keys) removeAt(index_.find(k)->second);
    merged_ += keys.size();
  }
  ++frame_;
}

}  // namespace dpc
