#include "runtime/early_signature.h"

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>

namespace dpc {

namespace {
const float kMinCos = float(std::cos(EarlySignature::kDirectionToleranceDegrees * M_PI / 180.0));
}  // namespace

void EarlySignature::assignArrivals(const DirectSound& direct,
                                    std::span<const SpecularPath> paths,
                                    const ListenerFrame* frame) {
  const auto toListener = [frame](const glm::vec3& world) {
    return frame ? frame->toListener(world) : glm::vec3(0.f);
  };
  arrivals_.clear();
  spatial_ = frame != nullptr;
  if (frame) frame_ = *frame;
  hasDiffuse_ = false;
  directVisible_ = direct.visible;
  if (direct.visible)
    arrivals_.push_back(
        {0, double(direct.delaySeconds), direct.intensity, toListener(direct.direction)});
  const size_t first = arrivals_.size();
  for (const SpecularPath& p : paths)
    arrivals_.push_back({p.key, p.delaySeconds, p.intensity, toListener(p.direction)});
  // Paths in key order: the frame's order of discovery does not matter, their identity does.
  std::sort(arrivals_.begin() + std::ptrdiff_t(first), arrivals_.end(),
            [](const Arrival& a, const Arrival& b) {
              return a.key != b.key ? a.key < b.key : a.delaySeconds < b.delaySeconds;
            });
}

void EarlySignature::fillPoints() {
  points_.clear();
  for (const Arrival& a : arrivals_) points_.push_back({a.delaySeconds, a.intensity});
}

void EarlySignature::assignDiffuse(const EnergyResponse& early) {
  fillPoints();
  diffuse_ = LateShape::of(early, 0.0, points_);
  hasDiffuse_ = true;
}

void EarlySignature::assignDiffuse(const DirectionalEnergyResponse& early) {
  fillPoints();
  diffuse_ = LateShape::of(early, 0.0, points_);
  hasDiffuse_ = true;
}

bool EarlySignature::sameArrival(const Arrival& a, const Arrival& b, double toleranceDb) {
  if (a.key != b.key || std::abs(a.delaySeconds - b.delaySeconds) > kDelayToleranceSeconds)
    return false;
  const float strongest = std::max(a.intensity.max(), b.intensity.max());
  for (int k = 0; k < kNumBands; ++k) {
    const double x = a.intensity[k], y = b.intensity[k];
    if (std::max(x, y) < kBandFloor * double(strongest)) continue;
    if (x <= 0.0 || y <= 0.0 || std::abs(10.0 * std::log10(x / y)) > toleranceDb) return false;
  }
  return glm::dot(a.direction, b.direction) >= kMinCos ||
         (a.direction == glm::vec3(0.f) && b.direction == glm::vec3(0.f));
}

bool EarlySignature::sameArrivals(const EarlySignature& made, double toleranceDb) const {
  if (spatial_ != made.spatial_ || directVisible_ != made.directVisible_ ||
      arrivals_.size() != made.arrivals_.size())
    return false;
  // A turned head turns every arrival: the frames' axes within the direction tolerance.
  if (spatial_ && (glm::dot(frame_.forward, made.frame_.forward) < kMinCos ||
                   glm::dot(frame_.up, made.frame_.up) < kMinCos))
    return false;
  for (size_t i = 0; i < arrivals_.size(); ++i)
    if (!sameArrival(arrivals_[i], made.arrivals_[i], toleranceDb)) return false;
  return true;
}

bool EarlySignature::sameDiffuse(const EarlySignature& made, double toleranceDb) const {
  return hasDiffuse_ && made.hasDiffuse_ && diffuse_.maxDifferenceDb(made.diffuse_) <= toleranceDb &&
         diffuse_.levelDifferenceDb(made.diffuse_) <= toleranceDb;
}

}  // namespace dpc
