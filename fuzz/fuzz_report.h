// Shared by the fuzz targets and their replay (fuzz/replay_main.cpp): how far the last input
// got. A target calls accepted() when its loader read the input to the end and the target used
// the result, refused() with the loader's message when it was refused. The replay checks that
// every seed named valid-* is accepted, so that a seed the loader has come to refuse (a stale
// seed, which leaves the fuzzer mutating refusals only) fails ctest fuzz_replay:<target>.
// DPC_FUZZ_VERBOSE set: one line per input on stderr, "accepted: <what>" or "refused: <message>".
#pragma once

#include <cstdio>
#include <cstdlib>
#include <string>

namespace dpc::fuzz {

enum class Outcome { kNone, kAccepted, kRefused };

/// The last input's outcome (kNone until the target reports one; the replay resets it).
inline Outcome& lastOutcome() {
  static Outcome outcome = Outcome::kNone;
  return outcome;
}

inline bool verbose() {
  static const bool on = std::getenv("DPC_FUZZ_VERBOSE") != nullptr;
  return on;
}

/// The input was read to the end and used; `what` says what was built from it.
inline void accepted(const std::string& what) {
  lastOutcome() = Outcome::kAccepted;
  if (verbose()) std::fprintf(stderr, "accepted: %s\n", what.c_str());
}

/// accepted() for a loaded dpc::SceneDesc: its triangle, source, moving-object and warning
/// counts (a template, so that targets without the scene layer need not include scene/scene.h).
template <class Scene>
void acceptedScene(const Scene& scene) {
  accepted(std::to_string(scene.mesh.triangles.size()) + " triangles, " +
           std::to_string(scene.sources.size()) + " sources, " +
           std::to_string(scene.objects.size()) + " moving objects, " +
           std::to_string(scene.warnings.size()) + " warnings");
}

/// The input was refused with `message` (the loader's one line naming file and field).
inline void refused(const char* message) {
  lastOutcome() = Outcome::kRefused;
  if (verbose()) std::fprintf(stderr, "refused: %s\n", message);
}

}  // namespace dpc::fuzz
