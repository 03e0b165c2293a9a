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
/// Frames in a row a change must last before it is logged: a listener that few rays reach
/// flickers between a frame with a hit and one without, which is no change of place.
inline constexpr int kSilenceSettleFrames = 3;

/// Whether listener `listener` hears source `source` this frame: its direct sound (through
/// edges, slits and transmitting surfaces included), an exact specular path or any energy in
/// its response, or the pair plays from a bake (`baked`, may be null). The thread that runs
/// the simulation's frames (it reads their results); no allocation.
bool hearsSource(const Simulation& sim, size_t source, size_t listener, const BakedPlayback* baked);

class SilenceWatch {
 public:
  /// After each frame that traced listener `listener` (name as in the scene) at `position`,
  /// metres: logs a warning (common/log.h) once it has heard none of the sources for
  /// kSilenceSettleFrames frames in a row and heard them before (or from its first frame), a
  /// note once it has heard them again as long. Propagation thread; allocates when a listener
  /// is first seen and for a line it logs.
  void update(const Simulation& sim, size_t listener, const std::string& name, glm::vec3 position,
              const BakedPlayback* baked);
  /// Lines logged so far (at most kMaxSilenceLines). Propagation thread.
  int lines() const { return lines_; }

 private:
  void log(bool silent, size_t listener, const std::string& name, glm::vec3 position,
           size_t sources);
  struct State {
    signed char logged = -1;  ///< -1 nothing logged (hearing assumed), 0 silent, 1 hears
    signed char last = -1;    ///< the last frame's: 0 silent, 1 hears
    int run = 0;              ///< frames in a row with `last`
  };
  std::vector<State> state_;  ///< per listener
  int lines_ = 0;
};

}  // namespace dpc
