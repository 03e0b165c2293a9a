// SilenceWatch: one log line when a live listener stops hearing every source, and one when it
// hears again. A listener a host moves (the plugin's ports, the C API, the Python binding) can
// leave the room or enter a solid mid-session; the setup check (engine/setup_check.h) only
// looks at the scene's positions before a run, and the sound alone (silence) does not say why.
#pragma once

#include <glm/vec3.hpp>
#include <string>
#include <vector>

#include "engine/simulation.h"
#include "runtime/baked_playback.h"

namespace dpc {

/// Changes logged per session at most; the following ones are left out, and the line that
/// reaches this bound says so.
inline constexpr int kMaxSilenceLines = 20;

/// Whether listener `listener` hears source `source` this frame: its direct sound (through
/// edges, slits and transmitting surfaces included), an exact specular path or any energy in
/// its response, or the pair plays from a bake (`baked`, may be null). Any thread; no
/// allocation.
bool hearsSource(const Simulation& sim, size_t source, size_t listener, const BakedPlayback* baked);

class SilenceWatch {
 public:
  /// After each frame that traced listener `listener` (name as in the scene) at `position`,
  /// metres: logs a warning (common/log.h) when it hears none of the sources and did before
  /// (or this is its first frame), a note when it hears them again. Propagation thread;
  /// allocates only for a line it logs.
  void update(const Simulation& sim, size_t listener, const std::string& name, glm::vec3 position,
              const BakedPlayback* baked);
  /// Lines logged so far (at most kMaxSilenceLines). Propagation thread.
  int lines() const { return lines_; }

 private:
  void log(bool silent, size_t listener, const std::string& name, glm::vec3 position,
           size_t sources);
  std::vector<signed char> heard_;  ///< per listener: -1 not yet traced, 0 silent, 1 hears
  int lines_ = 0;
};

}  // namespace dpc
