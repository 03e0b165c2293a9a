#include "synthesis/source_clusters.h"

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <stdexcept>

namespace dpc {

namespace {
double angleBetween(const glm::vec3& a, const glm::vec3& b) {
  return std::acos(std::clamp(double(glm::dot(a, b)), -1.0, 1.0));
}
}  // namespace

SourceClusters::SourceClusters(size_t sources, int buses, double maxAngleRadians,
                               double hysteresis)
    : maxAngle_(maxAngleRadians), hysteresis_(hysteresis) {
  if (sources == 0 || buses < 1 || !(maxAngleRadians > 0.0) || !(hysteresis >= 0.0))
    throw std::invalid_argument("SourceClusters: need sources, buses, an angle and hysteresis");
  assignment_.assign(sources, kNone);
  previous_.assign(sources, kNone);
  forced_.assign(sources, 0);
  direction_.assign(sources, glm::vec3(1.f, 0.f, 0.f));
  seed_.assign(size_t(buses), kNone);
  sum_.assign(size_t(buses), glm::vec3(0.f));
  mean_.assign(size_t(buses), glm::vec3(0.f));
}

int SourceClusters::occupied() const {
  return int(std::count_if(seed_.begin(), seed_.end(), [](int s) { return s != kNone; }));
}

void SourceClusters::computeMeans() {
  std::fill(sum_.begin(), sum_.end(), glm::vec3(0.f));
  for (size_t s = 0; s < previous_.size(); ++s)
    if (previous_[s] != kNone && !forced_[s]) sum_[size_t(previous_[s])] += direction_[s];
  for (size_t k = 0; k < sum_.size(); ++k) {
    const float len = glm::length(sum_[k]);
    mean_[k] = len > 1e-6f ? sum_[k] / len : glm::vec3(0.f);
  }
}

bool SourceClusters::stays(size_t s, std::span<const glm::vec3> sources,
                           const Visible& visible) const {
  const int k = previous_[s];
  if (k == kNone || seed_[size_t(k)] == kNone || forced_[s]) return false;
  if (glm::length(mean_[size_t(k)]) == 0.f) return false;
  if (angleBetween(direction_[s], mean_[size_t(k)]) > maxAngle_ * (1.0 + hysteresis_))
    return false;
  const int seed = seed_[size_t(k)];
  return size_t(seed) == s || visible(sources[s], sources[size_t(seed)]);
}

int SourceClusters::bestFit(size_t s, std::span<const glm::vec3> sources,
                            const Visible& visible) const {
  int best = kNone;
  double bestAngle = maxAngle_;
  for (size_t k = 0; k < seed_.size(); ++k) {
    if (seed_[k] == kNone) continue;
    const float len = glm::length(sum_[k]);
    if (len < 1e-6f) continue;
    const double a = angleBetween(direction_[s], sum_[k] / len);
    if (a > bestAngle) continue;
    if (!visible(sources[s], sources[size_t(seed_[k])])) continue;
    best = int(k);
    bestAngle = a;
  }
  return best;
}

void SourceClusters::assign(size_t s, int k, bool forced) {
  assignment_[s] = k;
  forced_[s] = forced;
  if (forced) return;  // the members that fit keep their mean
  if (seed_[size_t(k)] == kNone) seed_[size_t(k)] = int(s);
  sum_[size_t(k)] += direction_[s];
}

int SourceClusters::freeBus() const {
  for (size_t k = 0; k < seed_.size(); ++k)
    if (seed_[k] == kNone) return int(k);
  return kNone;
}

int SourceClusters::forcedCluster(size_t s) const {
  const int k = previous_[s];
  if (k != kNone && seed_[size_t(k)] != kNone) return k;
  return nearestMean(s);
}

int SourceClusters::nearestMean(size_t s) const {
  int best = 0;
  double bestAngle = 1e9;
  for (size_t k = 0; k < sum_.size(); ++k) {
    const float len = glm::length(sum_[k]);
    if (len < 1e-6f) continue;
    const double a = angleBetween(direction_[s], sum_[k] / len);
    if (a < bestAngle) best = int(k), bestAngle = a;
  }
  return best;
}

void SourceClusters::keepSeeds(size_t n, std::span<const glm::vec3> sources,
                               const Visible& visible, std::span<const bool> active) {
  for (int& seed : seed_) {
    const bool keep = seed != kNone && size_t(seed) < n &&
                      (active.empty() || active[size_t(seed)]) &&
                      stays(size_t(seed), sources, visible);
    if (!keep) seed = kNone;
  }
  std::fill(assignment_.begin(), assignment_.end(), kNone);
  std::fill(forced_.begin(), forced_.end(), 0);
  std::fill(sum_.begin(), sum_.end(), glm::vec3(0.f));
  for (size_t k = 0; k < seed_.size(); ++k)
    if (seed_[k] != kNone) assign(size_t(seed_[k]), int(k));
}

void SourceClusters::countMoves(size_t n) {
  maxRadius_ = 0.0;
  for (size_t s = 0; s < n; ++s) {
    const int k = assignment_[s];
    if (k == kNone) continue;
    if (previous_[s] != kNone && previous_[s] != k) ++switches_;
    if (forced_[s]) continue;  // beyond the bound by definition, counted in forcedJoins_
    const float len = glm::length(sum_[size_t(k)]);
    if (len > 1e-6f) maxRadius_ = std::max(maxRadius_, angleBetween(direction_[s], sum_[size_t(k)] / len));
  }
}

void SourceClusters::update(const glm::vec3& listener, std::span<const glm::vec3> sources,
                            const Visible& visible, std::span<const bool> active) {
  const size_t n = std::min(sources.size(), assignment_.size());
  for (size_t s = 0; s < n; ++s) {
    const glm::vec3 d = sources[s] - listener;
    const float len = glm::length(d);
    direction_[s] = len > 1e-6f ? d / len : glm::vec3(1.f, 0.f, 0.f);
  }
  previous_ = assignment_;
  computeMeans();
  keepSeeds(n, sources, visible, active);
  // Members that stay, then the rest: the best fit, a free bus, or the nearest cluster.
  auto isActive = [&](size_t s) { return active.empty() || active[s]; };
  for (size_t s = 0; s < n; ++s)
    if (isActive(s) && assignment_[s] == kNone && stays(s, sources, visible))
      assign(s, previous_[s]);
  for (size_t s = 0; s < n; ++s) {
    if (!isActive(s) || assignment_[s] != kNone) continue;
    int k = bestFit(s, sources, visible);
    if (k == kNone) k = freeBus();
    const bool forced = k == kNone;
    if (forced) {
      k = forcedCluster(s);
      ++forcedJoins_;
    }
    assign(s, k, forced);
  }
  countMoves(n);
}

}  // namespace dpc
