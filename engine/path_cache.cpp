#include "engine/path_cache.h"

#include "engine/path_cache_weightings.h"

namespace dpc {

void PathTracingEstimator::endFrame(const FrameGroups& frame, uint64_t raysEmitted,
                                    float speedOfSound, EnergyResponse& out,
                                    ArrivalSink* directional) const {
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
                                   double framePeriodSeconds, size_t budgetBytes, CachePool* pool)
    : store_(makeWeightedStore(weighting, tauSeconds, framePeriodSeconds, budgetBytes, pool)) {}

DiffusePathCache::~DiffusePathCache() = default;

void DiffusePathCache::endFrame(const FrameGroups& frame, uint64_t raysEmitted, float speedOfSound,
                                EnergyResponse& out, ArrivalSink* directional) {
  store_->endFrame(frame, raysEmitted, speedOfSound, out, directional);
}

void DiffusePathCache::clear() {
  store_->clear();
}
size_t DiffusePathCache::entryCount() const {
  return store_->entryCount();
}
size_t DiffusePathCache::coarseEntryCount() const {
  return store_->coarseEntryCount();
}
size_t DiffusePathCache::maxEntries() const {
  return store_->capacity().entries;
}
size_t DiffusePathCache::budgetBytes() const {
  return store_->budgetBytes();
}
size_t DiffusePathCache::bytes() const {
  return store_->capacity().bytes;
}
uint64_t DiffusePathCache::refusedGrowths() const {
  return store_->refusedGrowths();
}
void DiffusePathCache::growDeferred() {
  store_->growDeferred();
}
size_t DiffusePathCache::bytesInUse() const {
  return store_->bytesInUse();
}
size_t DiffusePathCache::coarseBinsPerOctave() const {
  return store_->coarseBinsPerOctave();
}
uint32_t DiffusePathCache::lifetimeFrames() const {
  return store_->shape().lifetime;
}
double DiffusePathCache::emaCoefficient() const {
  return store_->shape().emaCoefficient;
}
uint64_t DiffusePathCache::mergedEntries() const {
  return store_->mergedEntries();
}
double DiffusePathCache::coarseEnergyFraction() const {
  return store_->coarseEnergyFraction();
}
uint32_t DiffusePathCache::oldestEntryFrame() const {
  return store_->oldestEntryFrame();
}

}  // namespace dpc
