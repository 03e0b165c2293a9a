// The bake's progress on stderr: a bar with the units done (probes, or the wave band's time
// steps), units per second and the estimated time left, redrawn in place on a terminal (at
// most every kRedrawSeconds for stepTo) and printed every 10 % otherwise. Rank 0's main
// thread; allocates nothing after construction; no errors.
#pragma once

#include <chrono>
#include <cstddef>

namespace dpc::bake {

class Progress {
 public:
  /// Least time between two redraws of stepTo on a terminal, seconds.
  static constexpr double kRedrawSeconds = 0.25;
  /// total: units to do in this run; already: units the file held before it; unit: their
  /// name, plural ("probes").
  Progress(size_t total, size_t already, bool quiet, const char* unit = "probes");
  /// One more probe committed.
  void step();
  /// `done` of `total` units done in this run (a total known once the work started).
  void stepTo(size_t done, size_t total);
  /// Ends the line (after the last step).
  void finish();
  /// Probes per second of this run so far (0 before the first).
  double rate() const;
  double elapsedSeconds() const;
  /// Probes committed in this run.
  size_t done() const { return done_; }

 private:
  void draw() const;
  size_t total_, already_, done_ = 0;
  bool quiet_, terminal_;
  const char* unit_;
  int lastDecile_ = -1;
  double lastDraw_ = -1.0;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace dpc::bake
