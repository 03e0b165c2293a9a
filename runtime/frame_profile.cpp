#include "runtime/frame_profile.h"

#include <algorithm>
#include <cmath>

namespace dpc {
namespace {

uint64_t toNs(double seconds) { return uint64_t(std::llround(std::max(seconds, 0.0) * 1e9)); }

}  // namespace

const char* FrameProfile::name(Stage s) {
  static constexpr std::array<const char*, kStages> kNames = {
      "trace", "pairs", "synthesis", "partition", "publish", "snapshot", "frame"};
  return kNames[size_t(s)];
}

void FrameProfile::record(Stage s, double seconds) noexcept {
  const uint64_t ns = toNs(seconds);
  stats_[size_t(s)].record(ns, false);
  totalNs_[size_t(s)].fetch_add(ns, std::memory_order_relaxed);
}

void FrameProfile::recordPairCpu(double direct, double exact, double estimator) noexcept {
  pairCpuNs_[0].fetch_add(toNs(direct), std::memory_order_relaxed);
  pairCpuNs_[1].fetch_add(toNs(exact), std::memory_order_relaxed);
  pairCpuNs_[2].fetch_add(toNs(estimator), std::memory_order_relaxed);
}

FrameProfile::Snapshot FrameProfile::snapshot() const noexcept {
  Snapshot snap;
  for (size_t s = 0; s < size_t(kStages); ++s) {
    snap.stage[s] = stats_[s].snapshot();
    snap.totalSeconds[s] = double(totalNs_[s].load(std::memory_order_relaxed)) * 1e-9;
  }
  snap.directCpuSeconds = double(pairCpuNs_[0].load(std::memory_order_relaxed)) * 1e-9;
  snap.exactCpuSeconds = double(pairCpuNs_[1].load(std::memory_order_relaxed)) * 1e-9;
  snap.estimatorCpuSeconds = double(pairCpuNs_[2].load(std::memory_order_relaxed)) * 1e-9;
  return snap;
}

double FrameProfile::Snapshot::meanSeconds(Stage s) const {
  const uint64_t n = stage[size_t(s)].callbacks;
  return n > 0 ? totalSeconds[size_t(s)] / double(n) : 0.0;
}

std::array<FrameProfile::Snapshot::Row, FrameProfile::kStages> FrameProfile::Snapshot::rows()
    const {
  std::array<Row, kStages> out;
  for (int s = 0; s < kStages; ++s) {
    const audio::CallbackStats::Snapshot& st = stage[size_t(s)];
    out[size_t(s)] = Row{name(Stage(s)), st.callbacks, 1e3 * meanSeconds(Stage(s)),
                         double(st.quantileNs(0.5)) * 1e-6, double(st.quantileNs(0.95)) * 1e-6,
                         double(st.maxNs) * 1e-6};
  }
  return out;
}

}  // namespace dpc
