// AdaptiveRays: the live propagation thread's ray-count controller (docs/live.md, "Adaptive
// rays"). After each frame it is told how long the frame took, and how old the pose it traced
// was when its IR was ready, and picks the rays per source of the next one so that
//   - a frame fits in the frame period (1 / frame_rate) instead of falling behind, and
//   - the motion-to-sound latency (pose published -> IR ready, plus the audio thread's pick-up
//     of at most one block, which the caller adds) stays under a target.
// With load = max(elapsed / period, latency / (kLatencyMargin * target)):
//
//   load > 1          rays *= kTarget / load                    (down, proportionally)
//   load < kTarget    rays *= min(kGrowth, kTarget / load)      (back up)
//   otherwise         unchanged (hysteresis: no oscillation around the budget)
//
// always within [floor, scene rays], floor = max(scene rays / 16, min(256, scene rays)). The
// tracing time is close to proportional to the rays; the part that is not (IR synthesis,
// partitioning) and the pose's age make a reduction undershoot, and the next frames correct it.
//
// The diffuse path cache stays unbiased: each frame's estimate is I_f / N_f with N_f the rays
// that frame really traced (TraceStats::rays, passed to the estimator by Simulation), so
// frames of different ray counts average to the same expectation; fewer rays only add variance.
//
// Plain arithmetic, no allocation, no clock: the caller measures (or, in tests, injects) the
// frame's duration and latency. One thread (the propagation thread).
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

namespace dpc {

class AdaptiveRays {
 public:
  /// Aim: a frame's load is at most this fraction of its budget (room for the rest of the loop
  /// and for frame-to-frame variation).
  static constexpr double kTarget = 0.8;
  /// Largest growth per frame (x1.25: back from 1/16 to full rays in 13 frames, under a
  /// second at 15 frames/s, without overshooting into a late frame at once).
  static constexpr double kGrowth = 1.25;
  /// The latency target bounds nearly every frame, not the typical one: the controller keeps
  /// the latency it sees under this fraction of the target, because the next frame's latency
  /// differs from the last one's by the frame-to-frame variation (and the pose's age) that it
  /// cannot foresee.
  static constexpr double kLatencyMargin = 0.9;
  /// The floor: at least 1/16 of the scene's rays, and 256 rays (or all of them if fewer).
  static constexpr int kFloorDivisor = 16;
  static constexpr int kFloorRays = 256;

  /// sceneRays: rays per source the scene asks for (the ceiling, and the start).
  /// framePeriodSeconds: 1 / frame_rate. latencyTargetSeconds: the motion-to-sound latency to
  /// stay under (seconds; infinite or not positive: none, the period alone bounds a frame).
  AdaptiveRays(int sceneRays, double framePeriodSeconds,
               double latencyTargetSeconds = std::numeric_limits<double>::infinity())
      : ceiling_(std::max(1, sceneRays)),
        floor_(std::max(ceiling_ / kFloorDivisor, std::min(kFloorRays, ceiling_))),
        period_(framePeriodSeconds),
        latencyTarget_(latencyTargetSeconds > 0.0 ? latencyTargetSeconds
                                                  : std::numeric_limits<double>::infinity()),
        rays_(ceiling_) {}

  /// Rays per source for the next frame.
  int rays() const { return rays_; }
  int floor() const { return floor_; }
  int ceiling() const { return ceiling_; }

  /// The frame just run (at rays()) took elapsedSeconds, and its IR was ready latencySeconds
  /// after the pose it traced was published (plus the audio pick-up; NaN or omitted: not
  /// known, the period alone counts). Sets rays() for the next frame and returns it. A
  /// non-finite or non-positive duration changes nothing.
  int update(double elapsedSeconds, double latencySeconds = std::nan("")) {
    if (!(elapsedSeconds > 0.0) || !std::isfinite(elapsedSeconds) || !(period_ > 0.0)) return rays_;
    double load = elapsedSeconds / period_;
    if (latencySeconds > 0.0 && std::isfinite(latencySeconds) && std::isfinite(latencyTarget_))
      load = std::max(load, latencySeconds / (kLatencyMargin * latencyTarget_));
    const double fit = kTarget / load;  // scale that would hit the target
    double next = rays_;
    if (load > 1.0)
      next = rays_ * fit;
    else if (fit > 1.0)
      next = rays_ * std::min(kGrowth, fit);
    rays_ = int(std::clamp(std::round(next), double(floor_), double(ceiling_)));
    return rays_;
  }

 private:
  int ceiling_, floor_;
  double period_;         ///< seconds
  double latencyTarget_;  ///< seconds (infinite: none)
  int rays_;
};

}  // namespace dpc
