#include "runtime/adaptive_rays.h"

#include <algorithm>

namespace dpc {

AdaptiveRays::AdaptiveRays(int sceneRays, double framePeriodSeconds, double latencyTargetSeconds)
    : ceiling_(std::max(1, sceneRays)),
      floor_(floorFor(sceneRays)),
      first_(std::max(floor_, ceiling_ / kFirstFrameDivisor)),
      period_(framePeriodSeconds),
      latencyTarget_(latencyTargetSeconds > 0.0 ? latencyTargetSeconds
                                                : std::numeric_limits<double>::infinity()),
      rays_(first_),
      last_(first_),
      jitterAbs_(kInitialJitter * (std::isfinite(latencyTarget_) ? latencyTarget_ : period_) /
                 kSigmaPerMad) {}

int AdaptiveRays::floorFor(int sceneRays) {
  const int ceiling = std::max(1, sceneRays);
  return std::max(ceiling / kFloorDivisor, std::min(kFloorRays, ceiling));
}

int AdaptiveRays::update(double elapsedSeconds, double latencySeconds, double raysSeconds,
                         double knownSeconds) {
  if (!(elapsedSeconds > 0.0) || !std::isfinite(elapsedSeconds) || !(period_ > 0.0)) return rays_;
  const bool split = raysSeconds >= 0.0 && raysSeconds <= elapsedSeconds;
  last_ = rays_;
  if (!split) {
    model_ = false;
    rays_ = clampRays(proportionalRays(elapsedSeconds, latencySeconds));
    return rays_;
  }
  if (!(knownSeconds >= 0.0) || !std::isfinite(knownSeconds)) knownSeconds = 0.0;
  learn(elapsedSeconds, latencySeconds, raysSeconds, knownSeconds);
  model_ = true;
  return raysFor(knownSeconds);
}

int AdaptiveRays::raysFor(double knownSeconds) {
  if (!model_) return rays_;
  if (!(knownSeconds >= 0.0) || !std::isfinite(knownSeconds)) knownSeconds = 0.0;
  if (!(perRay_ > 0.0)) return rays_ = clampRays(last_ * kGrowth);  // nothing scales with rays
  double next = (kTarget * period_ - fixedFrame_) / perRay_;
  if (!std::isnan(fixedLatency_) && std::isfinite(latencyTarget_))
    next = std::min(next, (aim() - knownSeconds - fixedLatency_) / perRay_);
  rays_ = clampRays(std::min(next, last_ * kGrowth));
  return rays_;
}

double AdaptiveRays::aim() const {
  return std::min(kLatencyMargin * latencyTarget_,
                  latencyTarget_ - kJitterSigmas * jitterSeconds());
}

bool AdaptiveRays::hasLatency(double latencySeconds) const {
  return latencySeconds > 0.0 && std::isfinite(latencySeconds) && std::isfinite(latencyTarget_);
}

double AdaptiveRays::proportionalRays(double elapsedSeconds, double latencySeconds) const {
  double load = elapsedSeconds / period_;
  if (hasLatency(latencySeconds))
    load = std::max(load, latencySeconds / (kLatencyMargin * latencyTarget_));
  const double fit = kTarget / load;  // scale that would hit the target
  if (load > 1.0) return rays_ * fit;
  if (fit > 1.0) return rays_ * std::min(kGrowth, fit);
  return rays_;
}

void AdaptiveRays::learn(double elapsedSeconds, double latencySeconds, double raysSeconds,
                         double knownSeconds) {
  const bool timed = hasLatency(latencySeconds);
  double perRay = raysSeconds / double(rays_);
  double fixedFrame = elapsedSeconds - raysSeconds;
  double fixedLatency = latencySeconds - knownSeconds - raysSeconds;
  if (!std::isnan(fixedFrame_)) {
    // How far this frame missed the model's prediction, before the model learns from it. One
    // outlier frame moves sigma, F and c r by at most kClipSigmas sigma (Huber's clipping).
    const double bound = kClipSigmas * jitterSeconds();
    const bool latencyModel = timed && !std::isnan(fixedLatency_);
    const double predicted =
        (latencyModel ? knownSeconds + fixedLatency_ : fixedFrame_) + perRay_ * rays_;
    const double miss = (latencyModel ? latencySeconds : elapsedSeconds) - predicted;
    blend(jitterAbs_, std::min(std::abs(miss), bound), kJitterWeight);
    fixedFrame = std::clamp(fixedFrame, fixedFrame_ - bound, fixedFrame_ + bound);
    if (!std::isnan(fixedLatency_))
      fixedLatency = std::clamp(fixedLatency, fixedLatency_ - bound, fixedLatency_ + bound);
    perRay = std::clamp(perRay, perRay_ - bound / rays_, perRay_ + bound / rays_);
  }
  if (timed) blend(fixedLatency_, fixedLatency, kModelWeight);
  blend(fixedFrame_, fixedFrame, kModelWeight);
  blend(perRay_, perRay, kModelWeight);
}

void AdaptiveRays::blend(double& average, double sample, double weight) {
  average = std::isnan(average) ? sample : average + weight * (sample - average);
}

int AdaptiveRays::clampRays(double next) const {
  if (std::isnan(next)) return rays_;
  return int(std::clamp(std::round(next), double(floor_), double(ceiling_)));
}

}  // namespace dpc
