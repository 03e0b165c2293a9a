#include "plugins/lv2/plugin.h"

#include <lv2/atom/atom.h>
#include <lv2/patch/patch.h>

namespace dpc::lv2 {

void Uris::map(LV2_URID_Map* m) {
  atomPath = m->map(m->handle, LV2_ATOM__Path);
  atomUrid = m->map(m->handle, LV2_ATOM__URID);
  atomObject = m->map(m->handle, LV2_ATOM__Object);
  atomSequence = m->map(m->handle, LV2_ATOM__Sequence);
  patchSet = m->map(m->handle, LV2_PATCH__Set);
  patchGet = m->map(m->handle, LV2_PATCH__Get);
  patchProperty = m->map(m->handle, LV2_PATCH__property);
  patchValue = m->map(m->handle, LV2_PATCH__value);
  sceneParam = m->map(m->handle, kSceneParam);
}

Plugin::Plugin() {
  for (int i = 0; i < kPosePorts; ++i) latestPose[i].store(kPoseRanges[i].fallback);
}

void Plugin::recordPath(const Scene& s) {
  pathSeq.fetch_add(1, std::memory_order_acq_rel);
  const size_t n = s.isDefault ? 0 : std::min(s.path.size(), kMaxPath - 1);
  std::memcpy(savedPath, s.path.data(), n);
  savedPath[n] = '\0';
  pathSeq.fetch_add(1, std::memory_order_release);
}

std::string Plugin::readPath() const {
  char copy[kMaxPath];
  for (;;) {
    const uint32_t before = pathSeq.load(std::memory_order_acquire);
    if (before & 1u) continue;
    std::memcpy(copy, savedPath, kMaxPath);
    std::atomic_thread_fence(std::memory_order_acquire);
    if (pathSeq.load(std::memory_order_relaxed) == before) break;
  }
  copy[kMaxPath - 1] = '\0';
  return copy;
}

Pose Plugin::latest() const {
  Pose q{};
  for (int i = 0; i < kPosePorts; ++i) q.v[i] = latestPose[i].load(std::memory_order_relaxed);
  return q;
}

bool Plugin::noteClamped() {
  uint32_t fresh = 0;
  for (int i = 0; i < kPosePorts; ++i) {
    const float v = raw(i);
    const uint32_t bit = 1u << i;
    if (clampToPort(kPoseRanges[i], v) == v || (clamped.load(std::memory_order_relaxed) & bit))
      continue;
    firstOutside[i].store(v, std::memory_order_relaxed);
    fresh |= bit;
  }
  if (fresh) clamped.fetch_or(fresh, std::memory_order_release);
  return fresh != 0;
}

void reportClamped(Plugin* p) {
  const uint32_t pending = p->clamped.load(std::memory_order_acquire) & ~p->reported;
  for (int i = 0; i < kPosePorts; ++i) {
    if (!(pending & (1u << i))) continue;
    const PortRange& r = kPoseRanges[i];
    const float v = p->firstOutside[i].load(std::memory_order_relaxed);
    const char* format =
        "dpc: port %s: %g is outside its range [%g, %g]; clamped to %g (logged "
        "once)\n";
    const double to = clampToPort(r, v);
    lv2_log_warning(&p->logger, format, r.symbol, double(v), double(r.min), double(r.max), to);
  }
  p->reported |= pending;
}

void logError(Plugin* p, const char* what) {
  const char* sep = what ? ": " : "";
  if (!what) what = "";
  lv2_log_error(&p->logger, "dpc: %s%s%s\n", what, sep, dpc_last_error());
}

void publish(dpc_engine* e, const Pose& q) {
  dpc_engine_set_listener_pose(e, dpc_engine_selected_listener(e), q.v[0], q.v[1], q.v[2], q.v[3],
                               0.f);
  dpc_engine_set_source_position(e, 0, q.v[4], q.v[5], q.v[6]);
}

}  // namespace dpc::lv2
