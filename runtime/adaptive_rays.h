// AdaptiveRays: the live propagation thread's ray-count controller (docs/live.md, "Adaptive
// rays"). After each frame it is told how long the frame took, how old the pose it traced was
// when its IR was ready, and (when known) how much of that time scaled with the rays. It picks
// the rays per source of the next frame so that
//   - a frame fits in the frame period (1 / frame_rate) instead of falling behind, and
//   - the motion-to-sound latency (pose published -> IR ready, plus the audio thread's pick-up,
//     which the caller adds) stays under a target in nearly every frame.
//
// Model-based control (when the caller gives the rays' share of the frame): a frame's
// latency is
//   T(r) = K + F + c r
// with K the part known when the frame starts (its pose's age then, the audio pick-up), F the
// part that does not scale with the rays r (IR synthesis, partitioning, the direct sound and
// diffraction) and c the seconds per ray (the tracing and the hits' cache updates). F and c
// are exponential moving averages of each frame's measured split; sigma is the spread (from
// the mean absolute deviation) of the latency (without a target: the frame's duration) around
// what the model predicted for that frame: the variation the controller cannot foresee (the
// machine, the scene). A frame starting with known part K traces the rays whose predicted
// latency is
//   min(kLatencyMargin * target, target - kJitterSigmas * sigma)
// and whose predicted duration F + c r is kTarget * period, whichever is fewer; up by at most
// kGrowth over the last frame, down at once. A proportional rule (time ~ r) would undershoot
// where F dominates: halving the rays then barely shortens the frame, and the rays sit far
// below what fits. Taking the pose's age as known rather than as variation keeps it out of
// sigma: a 10 ms control tick's age is uniform over 10 ms, sigma 2.9 ms, which would cost
// 2 sigma of every frame's budget.
//
// Without the split (update(elapsed[, latency])), the proportional rule: with
// load = max(elapsed / period, latency / (kLatencyMargin * target)),
//   load > 1          rays *= kTarget / load                    (down, proportionally)
//   load < kTarget    rays *= min(kGrowth, kTarget / load)      (back up)
//   otherwise         unchanged (hysteresis: no oscillation around the budget)
//
// Always within [floor, scene rays], floor = max(scene rays / 16, min(256, scene rays)).
//
// The diffuse path cache stays unbiased: each frame's estimate is I_f / N_f with N_f the rays
// that frame really traced (TraceStats::rays, passed to the estimator by Simulation), so
// frames of different ray counts average to the same expectation; fewer rays only add variance.
//
// Plain arithmetic, no allocation, no clock: the caller measures (or, in tests, injects) the
// frame's times. One thread (the propagation thread).
#pragma once

#include <cmath>
#include <limits>

namespace dpc {

class AdaptiveRays {
 public:
  /// Aim: a frame's duration is at most this fraction of the period (room for the rest of the
  /// loop and for frame-to-frame variation); the proportional rule's hysteresis band.
  static constexpr double kTarget = 0.8;
  /// Largest growth per frame (x1.25: back from 1/16 to full rays in 13 frames, under a
  /// second at 15 frames/s, without overshooting into a late frame at once).
  static constexpr double kGrowth = 1.25;
  /// The predicted latency never aims above this fraction of the target.
  static constexpr double kLatencyMargin = 0.9;
  /// Standard deviations of the unforeseen latency variation kept below the target. With the
  /// mean at target - 2 sigma, 2.3 % of frames of a normal spread pass the target, and none of
  /// a uniform one (the pose's age: its 95th percentile is 1.56 sigma above its mean).
  static constexpr double kJitterSigmas = 2.0;
  /// Weight of the newest frame in the moving averages of F, c (about the last 4 frames) and
  /// of the latency's absolute deviation (about the last 10).
  static constexpr double kModelWeight = 0.25;
  static constexpr double kJitterWeight = 0.1;
  /// sigma from the mean absolute deviation: sqrt(pi / 2) for a normal spread (1.15 for a
  /// uniform one). The absolute deviation, not its square, so that one slow frame (a page
  /// fault, another process) does not dominate the estimate.
  static constexpr double kSigmaPerMad = 1.2533141373155;
  /// A frame's deviation counts at most this many sigmas, in sigma and in F (Huber's clipping).
  static constexpr double kClipSigmas = 3.0;
  /// sigma before any frame was measured: this fraction of the latency target (of the frame
  /// period without one).
  static constexpr double kInitialJitter = 0.05;
  /// The floor: at least 1/16 of the scene's rays, and 256 rays (or all of them if fewer).
  static constexpr int kFloorDivisor = 16;
  static constexpr int kFloorRays = 256;
  /// The first frame, which nothing has measured yet, traces a quarter of the scene's rays
  /// (not below the floor): a short first frame for an early first sound, and rays enough
  /// that the first IR is not the floor's noisy one.
  static constexpr int kFirstFrameDivisor = 4;

  /// sceneRays: rays per source the scene asks for (the ceiling). framePeriodSeconds:
  /// 1 / frame_rate. latencyTargetSeconds: the motion-to-sound latency to stay under
  /// (seconds; infinite or not positive: none, the period alone bounds a frame).
  AdaptiveRays(int sceneRays, double framePeriodSeconds,
               double latencyTargetSeconds = std::numeric_limits<double>::infinity());

  /// Rays per source for the next frame; before any update(), firstFrameRays().
  int rays() const { return rays_; }
  int floor() const { return floor_; }
  /// The floor of a controller for sceneRays: max(sceneRays / 16, min(256, sceneRays)).
  static int floorFor(int sceneRays);
  int ceiling() const { return ceiling_; }
  int firstFrameRays() const { return first_; }

  /// The frame just run (at rays()) took elapsedSeconds, and its IR was ready latencySeconds
  /// after the pose it traced was published (plus the audio pick-up; NaN or omitted: not
  /// known, the period alone counts). raysSeconds: the part of the frame that scales with its
  /// rays (tracing, the hits' cache updates; NaN or omitted: not known, the proportional
  /// rule). knownSeconds: the part of its latency that was known when it started (its pose's
  /// age then, the audio pick-up; 0 when omitted). Sets rays() for a next frame whose known
  /// part is the same, and returns it. A non-finite or non-positive duration changes nothing.
  int update(double elapsedSeconds, double latencySeconds = std::nan(""),
             double raysSeconds = std::nan(""), double knownSeconds = 0.0);
  /// The rays of the frame starting now, whose latency's known part (its pose's age, the audio
  /// pick-up) is knownSeconds: the model's rays for what is left of the aim. Sets and returns
  /// rays(); without a model (no update with the split yet), rays() unchanged.
  int raysFor(double knownSeconds);

  /// The model's sigma: the latency's unforeseen variation, seconds.
  double jitterSeconds() const { return kSigmaPerMad * jitterAbs_; }

 private:
  bool hasLatency(double latencySeconds) const;
  double proportionalRays(double elapsedSeconds, double latencySeconds) const;
  void learn(double elapsedSeconds, double latencySeconds, double raysSeconds, double knownSeconds);
  double aim() const;  ///< the latency aimed at, seconds
  int clampRays(double next) const;
  static void blend(double& average, double sample, double weight);

  int ceiling_, floor_, first_;
  double period_;         ///< seconds
  double latencyTarget_;  ///< seconds (infinite: none)
  int rays_;
  int last_;            ///< rays of the frame last measured
  bool model_ = false;  ///< the last update had the split
  double fixedLatency_ = std::nan(""), fixedFrame_ = std::nan(""), perRay_ = std::nan("");
  double jitterAbs_;  ///< mean absolute deviation of the latency from the model, seconds
};

}  // namespace dpc
