// The bake's progress on stderr: a bar with probes done, probes per second and the estimated
// time left, redrawn in place on a terminal and printed every 10 % otherwise. Rank 0's main
// thread; allocates nothing after construction; no errors.
#pragma once

#include <chrono>
#include <cstddef>

namespace dpc::bake {

class Progress {
 public:
  /// total: probes to bake in this run; already: probes the file held before it.
  Progress(size_t total, size_t already, bool quiet);
  /// One more probe committed.
  void step();
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
  int lastDecile_ = -1;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace dpc::bake
