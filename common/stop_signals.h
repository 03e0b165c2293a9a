// Stop requests by signal: SIGINT (Ctrl-C), SIGTERM and SIGHUP end a program's run cleanly
// instead of killing it mid-write; so does SIGPIPE (the reader of its progress lines gone, as
// in `dpc-demo ... | head`: the write fails with EPIPE instead, and the run ends as stopped). The
// handler only records the signal; the program checks it at safe points (between rendered blocks,
// before committing its outputs), unwinds with Interrupted so that every temporary output file is
// removed, and exits with 128 + the signal's number after one line on stderr
// (common/program_main.h). A second SIGINT or SIGTERM a quarter of a second or more after the
// first (a person pressing Ctrl-C again while a long step runs; not the same request delivered
// twice, as a terminal and mpirun both do) ends the process at once by the signal's default
// action, and may leave a temporary output file (named OUT.tmp-XXXXXX) behind.
#pragma once

#include <stdexcept>
#include <string>

namespace dpc {

/// Thrown at a safe point after a stop signal: what() is "interrupted by SIGINT" (the signal's
/// name); signal() its number.
class Interrupted : public std::runtime_error {
 public:
  explicit Interrupted(int signal);
  int signal() const { return signal_; }

 private:
  int signal_;
};

/// Control thread, once at start: SIGINT, SIGTERM, SIGHUP and SIGPIPE set the stop request (the
/// first one wins) instead of ending the process. Throws std::runtime_error if a handler cannot be
/// installed.
void catchStopSignals();

/// Any thread (also the audio thread: one relaxed atomic load, no allocation): the number of
/// the stop signal received, 0 if none.
int stopSignal() noexcept;

/// Any thread but the audio thread: throws Interrupted if a stop signal was received.
void throwIfStopped();

}  // namespace dpc
