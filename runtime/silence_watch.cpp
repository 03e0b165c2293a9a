#include "runtime/silence_watch.h"

#include <cstdio>

#include "common/log.h"

namespace dpc {

bool hearsSource(const Simulation& sim, size_t source, size_t listener,
                 const BakedPlayback* baked) {
  if (baked && baked->plays(source, listener)) return true;
  const Simulation::SourceResult& r = sim.result(source, listener);
  if (r.direct.visible || !sim.specularPaths(source, listener).empty()) return true;
  const Bands total = r.energy.total();
  for (int b = 0; b < kNumBands; ++b)
    if (total[b] > 0.f) return true;
  return false;
}

void SilenceWatch::update(const Simulation& sim, size_t listener, const std::string& name,
                          glm::vec3 position, const BakedPlayback* baked) {
  if (sim.sourceCount() == 0) return;  // nothing to hear: a source-less session says nothing
  if (listener >= state_.size()) state_.resize(listener + 1);
  bool hears = false;
  for (size_t s = 0; s < sim.sourceCount() && !hears; ++s)
    hears = hearsSource(sim, s, listener, baked);
  State& st = state_[listener];
  const signed char now = hears ? 1 : 0;
  st.run = now == st.last ? st.run + 1 : 1;
  st.last = now;
  if (st.run < kSilenceSettleFrames) return;
  // Nothing logged yet: hearing is what a listener is expected to do, so only silence is said.
  const signed char before = st.logged < 0 ? 1 : st.logged;
  if (now != before) log(!hears, listener, name, position, sim.sourceCount());
  if (now != before || st.logged < 0) st.logged = now;
}

void SilenceWatch::log(bool silent, size_t listener, const std::string& name, glm::vec3 position,
                       size_t sources) {
  if (lines_ >= kMaxSilenceLines) return;
  ++lines_;
  char where[160];
  std::snprintf(where, sizeof where, "listener %zu \"%s\" at (%.2f, %.2f, %.2f) m", listener,
                name.c_str(), double(position.x), double(position.y), double(position.z));
  const std::string bound =
      lines_ == kMaxSilenceLines ? " (further changes of what it hears are not logged)" : "";
  if (silent)
    logMessage(LogLevel::kWarning,
               std::string(where) + " hears none of the " + std::to_string(sources) +
                   " sources: no direct sound and no path reaches it (outside the room, inside "
                   "a solid, or sealed off?)" + bound);
  else
    logMessage(LogLevel::kInfo, std::string(where) + " hears the sources again" + bound);
}

}  // namespace dpc
