// Work and memory estimate of a render before it starts, so that a setting that cannot finish
// or cannot fit is refused (or warned about) with its numbers instead of hanging or exhausting
// memory part-way (docs/scene-format.md, "Limits").
// Control thread; pure computation (no allocation beyond the message strings).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "scene/scene.h"

namespace dpc {

struct WorkloadEstimate {
  /// Reflection order a ray reaches on average before Russian roulette ends it: the order at
  /// which the least absorbing material's mean reflectance (1 - alpha) has fallen to the
  /// roulette threshold, plus its survivals' share (10 %), capped by max_order. Without
  /// roulette: max_order. Air absorption only shortens paths, so this is an upper estimate.
  double expectedOrder = 0;
  /// Ray segments traced per propagation frame: rays x (expectedOrder + 1) x sources.
  double segmentsPerFrame = 0;
  /// Segments over the render: segmentsPerFrame x frame_rate x duration (0 for live).
  double segmentsTotal = 0;
  /// Memory of the impulse responses in flight, bytes: sources x channels x ir_length x
  /// sample rate x kIrBytesPerSample (time-domain IRs, their partitioned spectra, the pooled
  /// sets being prepared, applied and recycled, and the synthesis buffers).
  double irBytes = 0;
  /// Memory of the diffuse path caches at most, bytes: the pairs grow their caches from one
  /// pool (propagation.cache_pool_mb), each up to propagation.cache_memory_mb, so the smaller
  /// of the pool and sources x listeners x cache_memory_mb.
  double cacheBytes = 0;
  /// Memory of the sources' dry signals, bytes: not estimated here (that needs the files'
  /// headers); the caller sets it (runtime/dry_signals.h, drySignalBytes) before
  /// checkWorkload, 0 if it holds none.
  double signalBytes = 0;
  /// The render's expected tracing time, seconds: segmentsTotal at kNominalSegmentsPerSecond
  /// (0 for live).
  double expectedSeconds = 0;
};

/// Bytes of memory per IR sample per output channel per source, measured: peak RSS of
/// dpc-demo on the shoebox with ir_length 2 s and 20 s (48 kHz, 64 rays, 0.5 s): +89 MB mono
/// (103 B per sample) and +543 MB binaural (157 B per sample and channel); the larger is used.
inline constexpr double kIrBytesPerSample = 160.0;
/// Ray segments per second a 2-core machine traces (docs/performance.md: the hall and the
/// shoebox run at 1.5e7 to 3e7): the scale of the time estimates.
inline constexpr double kNominalSegmentsPerSecond = 2e7;
/// Above this many segments in one frame the frame cannot finish in any useful time (about
/// 500 s at 2e7 segments/s): refused.
inline constexpr double kMaxSegmentsPerFrame = 1e10;
/// Above this many segments for the whole render (about 14 h at 2e7 segments/s): refused.
inline constexpr double kMaxSegmentsTotal = 1e12;
/// Above this many segments for the whole render (minutes or more): warned, with the numbers.
inline constexpr double kWarnSegmentsTotal = 1e10;

/// Memory a render may plan to use for its impulse responses and path caches, bytes: half of
/// the smaller of the machine's physical memory and the process's address-space and data
/// limits (the other half is for tracing, signals and the libraries). Two system calls.
double plannableMemoryBytes();

/// The automatic path cache pool (PropagationSettings::cachePoolMb = kCachePoolAuto): per
/// source-listener pair kAutoPoolPerPairMb at the reference paths per frame window, scaled by
/// rays_per_frame / 4096 x cache_tau x frame_rate / 15 (the hits a pair's cache keeps), never
/// below kAutoPoolMinMb. Measured: 1.8-2.0 MB of tables per pair at the reference (the market's
/// and the dense hall's 64 pairs, 4096 rays, tau 1 s, 15 frames/s; docs/performance.md), and a
/// cache grows its tables by doubling, so a pair just past 2 MB takes 4.
inline constexpr double kAutoPoolPerPairMb = 4.0;
inline constexpr double kAutoPoolMinMb = 128.0;

/// The pool's budget in MB: settings.cachePoolMb when given; for kCachePoolAuto the rule above
/// for `pairs` pairs, at most pairs x cache_memory_mb (no pair grows past its own budget), a
/// quarter of plannableMemoryBytes() and the field's limit (65536 MB). Pairs added after the
/// engine is built share the pool it was sized for. Any thread; two system calls for auto.
double cachePoolMbFor(const PropagationSettings& settings, size_t pairs);

/// durationSeconds: the render's length (<= 0: live, per-frame figures only); channels: output
/// channels (1 mono, 2 stereo or binaural).
WorkloadEstimate estimateWorkload(const SceneDesc& scene, const PropagationSettings& settings,
                                  int channels, double durationSeconds);

/// Throws InputError(scene.path, setting, "...") when the estimate exceeds kMaxSegmentsPerFrame,
/// kMaxSegmentsTotal or memoryLimitBytes (impulse responses, caches and dry signals together:
/// the field named is the largest of ir_length, cache_memory_mb (or cache_pool_mb) and
/// sources[].signal), naming the numbers and the settings
/// to lower. Returns one-line warnings (above kWarnSegmentsTotal, with the expected time)
/// otherwise.
std::vector<std::string> checkWorkload(const SceneDesc& scene, const PropagationSettings& settings,
                                       const WorkloadEstimate& estimate, double memoryLimitBytes);

}  // namespace dpc
