// Watchdog: rank 0's monitor of a distributed bake, so that a rank that dies is reported by
// dpc-bake itself in one line.
//
// A thread polls every kPollSeconds: whether a stop signal came (common/stop_signals.h: the
// user's SIGINT, SIGTERM or SIGHUP, or mpirun's after a rank died) and whether every other rank
// on this host is alive (its pid: kill(pid, 0) fails with ESRCH once the process is gone, and
// /proc/PID/stat reads Z while it is a zombie). On either it takes the commit lock, so the
// file stands between two commits (every stored probe flushed, the done mask exact, `complete`
// 0), prints one line naming the file, the rank that stopped (when one on this host did), the
// probes committed and the --resume command, and ends the process with status 1 (a rank
// stopped) or 128 + the signal's number without
// MPI_Finalize (which would wait for the dead rank). Why a thread: after a rank dies, mpirun
// sends the others SIGTERM and SIGKILL 1 s later (Open MPI's odls_base_sigkill_timeout), while
// rank 0's main thread may be baking a probe for longer than that or waiting in MPI.
// Ranks on other hosts cannot be checked this way; their death reaches rank 0 as mpirun's
// signal, reported as an interruption that may be a rank's.
// Construction and destruction on rank 0's main thread; lock() and committed() there too.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace dpc::bake {

class Watchdog {
 public:
  /// How often the thread looks, seconds (well inside mpirun's 1 s before SIGKILL).
  static constexpr double kPollSeconds = 0.05;
  /// A rank to watch: its rank, and its pid when it runs on this host (else 0).
  struct Peer {
    int rank = 0;
    long pid = 0;
  };

  /// path: the bake file (messages); total: the file's probes; committed: probes stored
  /// before this run; ranks: the job's size. Stop signals: common/stop_signals.h.
  Watchdog(std::vector<Peer> peers, int ranks, std::string path, size_t total, size_t committed);
  ~Watchdog();
  Watchdog(const Watchdog&) = delete;
  Watchdog& operator=(const Watchdog&) = delete;

  /// Held around a commit: the watchdog ends the process only between commits.
  std::unique_lock<std::mutex> lock() { return std::unique_lock<std::mutex>(commit_); }
  /// One more probe committed (call with lock() held).
  void committed() { ++committed_; }

 private:
  void run();
  /// The first watched rank on this host that is gone, or -1.
  int goneRank() const;
  /// Prints the line and ends the process (holding the commit lock): status 1 when rank `gone`
  /// stopped, else 128 + the stop signal's number.
  [[noreturn]] void fail(int gone);

  std::vector<Peer> peers_;
  int ranks_;
  std::string path_;
  size_t total_;
  std::atomic<size_t> committed_;
  std::mutex commit_;
  std::mutex wake_;
  std::condition_variable cv_;
  bool done_ = false;
  std::thread thread_;
};

}  // namespace dpc::bake
