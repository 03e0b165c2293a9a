#include "apps/bake/watchdog.h"

#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>

#include "common/stop_signals.h"

namespace dpc::bake {
namespace {

/// Whether process pid has ended: no such process, or a zombie not yet reaped.
bool processGone(long pid) {
  if (::kill(pid_t(pid), 0) != 0 && errno == ESRCH) return true;
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  // "pid (comm) state ...": comm may hold spaces, so read up to the last ')'.
  std::string line;
  if (!std::getline(stat, line)) return false;
  const size_t close = line.rfind(')');
  return close != std::string::npos && close + 2 < line.size() && line[close + 2] == 'Z';
}

}  // namespace

Watchdog::Watchdog(std::vector<Peer> peers, int ranks, std::string path, size_t total,
                   size_t committed)
    : peers_(std::move(peers)),
      ranks_(ranks),
      path_(std::move(path)),
      total_(total),
      committed_(committed),
      thread_([this] { run(); }) {}

Watchdog::~Watchdog() {
  {
    std::lock_guard<std::mutex> g(wake_);
    done_ = true;
  }
  cv_.notify_all();
  thread_.join();
}

int Watchdog::goneRank() const {
  for (const Peer& p : peers_)
    if (p.pid > 0 && processGone(p.pid)) return p.rank;
  return -1;
}

void Watchdog::run() {
  std::unique_lock<std::mutex> g(wake_);
  const auto period = std::chrono::duration<double>(kPollSeconds);
  while (!cv_.wait_for(g, period, [this] { return done_; })) {
    const int gone = goneRank();
    // mpirun's signal follows a rank's death: looked at after the signal, the rank is gone.
    if (gone >= 0 || stopSignal() != 0) fail(gone >= 0 ? gone : goneRank());
  }
}

void Watchdog::fail(int gone) {
  const std::unique_lock<std::mutex> between = lock();  // never in the middle of a commit
  const size_t n = committed_;
  // On a terminal the progress bar's line is open: end it first.
  if (::isatty(STDERR_FILENO)) std::fputc('\n', stderr);
  if (gone >= 0)
    std::fprintf(stderr,
                 "dpc-bake: %s: rank %d of %d stopped; %zu of %zu probes committed, the file "
                 "is marked incomplete; dpc-bake --resume %s finishes it\n",
                 path_.c_str(), gone, ranks_, n, total_, path_.c_str());
  else
    std::fprintf(stderr,
                 "dpc-bake: %s: %s (the user's, or mpirun's after a rank on another host "
                 "stopped) with %zu of %zu probes committed; dpc-bake --resume %s finishes it\n",
                 path_.c_str(), Interrupted(stopSignal()).what(), n, total_, path_.c_str());
  std::fflush(stderr);
  std::_Exit(gone >= 0 ? 1 : 128 + stopSignal());
}

}  // namespace dpc::bake
