// Frames aligned to the host's pose publications. A host publishes the listener's pose at its
// own rate (a game at its frame rate, dpc-demo's control thread every 10 ms); a propagation
// frame starting on its own clock reads a pose that is on average half an interval old, and
// its IR reaches the listener that much staler (motion-to-sound latency, docs/live.md). When
// the pose in hand is stale and the next one is due soon enough for the frame still to end
// within its period (or, for frames longer than the period, soon enough to cost little of
// the frame rate), the frame waits for it.
//
// Plain arithmetic on steady_clock nanoseconds (runtime/host_poses.h steadyNowNs); any thread;
// no allocation; no errors.
#pragma once

#include <cstdint>

#include "runtime/pose_channel.h"

namespace dpc {

/// A pose older than this fraction of the host's interval is stale enough to wait for the
/// next (at a 10 ms interval: 2.5 ms; the wait then saves 2.5-10 ms of the pose's age).
inline constexpr double kStalePoseFraction = 0.25;
/// The next pose is awaited until this fraction of an interval past its due time (the host's
/// own timing jitter), then the frame starts with the pose it has.
inline constexpr double kPoseDueTolerance = 0.25;
/// A pose older than this many intervals means the stream has stopped (a paused host); up to
/// it, a late pose (a host's stall) is still awaited.
inline constexpr double kStoppedIntervals = 2.0;
/// A host that publishes less often than this is not a pose stream to align to (a paused
/// game, a host that sets the pose once): no wait.
inline constexpr int64_t kMaxPoseIntervalNs = 100'000'000;
/// A frame waits only while one as long as the last one, times this, still ends before the
/// next frame is due (live frames vary by a few per cent from one to the next: 1.1 is about
/// four of their standard deviations).
inline constexpr double kFrameLengthMargin = 1.1;
/// How often the waiting propagation thread looks for the new pose, ns.
inline constexpr int64_t kPosePollNs = 250'000;

/// An overdue frame (one that cannot end within its period however soon it starts) waits for
/// the host's next pose only while the wait costs at most this fraction of the frame.
inline constexpr double kOverdueWaitFraction = 0.25;

/// Until when (ns) a frame about to start at nowNs with `pose` in hand should wait for the
/// host's next pose, given that it must start by latestNs to end within its period.
/// overdueFrameNs > 0: the frame cannot end within its period however soon it starts (frames
/// as long as the last one, overdueFrameNs, run back to back), and latestNs does not apply. A
/// value <= nowNs: start now (the pose is fresh, the host publishes no steady stream, or the
/// next pose would come too late).
///
/// An overdue frame loses no deadline by waiting, and waits when the wait is at most
/// kOverdueWaitFraction of the frame: for frames of work W several host intervals P long
/// (W >> P: the pose's age at the frame's start, A, spread over [0, P)), the IR heard is on
/// average A + W + (interval between IRs) / 2 old, P/2 + 1.5 W when the frame starts at once
/// and 1.5 W + P/4 after the wait (age 0, the IRs W + P - A apart), and the pose's age leaves
/// every frame's motion-to-sound latency, for at most 1 / (1 + kOverdueWaitFraction) of the
/// frame rate. A longer wait (a host slower than the frames) would trade more frames, each
/// adding its rays to the path cache, for a fresher pose.
inline int64_t poseWaitUntilNs(const ListenerPose& pose, int64_t nowNs, int64_t latestNs,
                               int64_t overdueFrameNs = 0) {
  const int64_t interval = pose.intervalNs;
  if (interval <= 0 || interval > kMaxPoseIntervalNs || pose.publishedNs <= 0) return nowNs;
  const int64_t age = nowNs - pose.publishedNs;
  const int64_t tolerance = int64_t(kPoseDueTolerance * double(interval));
  // Fresh, or the stream has stopped.
  if (age < int64_t(kStalePoseFraction * double(interval)) ||
      age > int64_t(kStoppedIntervals * double(interval)))
    return nowNs;
  // The next pose is due one interval after this one; when that has passed (the host is late),
  // it may still come within the stopped limit.
  const int64_t due = age <= interval + tolerance ? interval + tolerance
                                                  : int64_t(kStoppedIntervals * double(interval));
  const int64_t until = pose.publishedNs + due;
  if (overdueFrameNs > 0)
    return until - nowNs <= int64_t(kOverdueWaitFraction * double(overdueFrameNs)) ? until : nowNs;
  return until <= latestNs ? until : nowNs;
}

}  // namespace dpc
