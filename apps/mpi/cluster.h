// The processes of one MPI job: Open MPI's ranks when the program was started by mpirun (and
// built with MPI), else one process alone. dpc-bake's data flow is a gather: every rank bakes
// its share of the probes and sends each finished probe to rank 0, the only process that
// touches the file (docs/bake.md says why a gather rather than parallel HDF5). dpc-wave's is
// a domain decomposition: every rank steps one slab of the wave grid and trades its edge
// slices with its neighbours each step (wave/fdtd.h, docs/wave.md).
// Main thread of each process only (MPI is initialised without thread support); allocates.
// MPI errors are returned, not fatal (MPI_ERRORS_RETURN on MPI_COMM_WORLD): a failed call
// throws std::runtime_error naming it, so rank 0 reports it in its own line. Open MPI's
// shared-memory single-copy transfer (CMA: the receiver reads the sender's memory) is turned
// off unless the user chose a mechanism: a receiver reading a rank that was killed aborts
// inside Open MPI ("Read -1, expected N, errno = 3") before dpc-bake can say anything; the
// copy through the shared-memory queues is what remains, progressed by both sides' MPI calls
// (rank 0 receives without blocking, so it bakes on while a message is in flight).
#pragma once

#include <cstddef>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "common/program_main.h"

namespace dpc {

class Cluster {
 public:
  /// Joins the MPI job when started by mpirun (OMPI_COMM_WORLD_SIZE or PMI_SIZE set) and the
  /// build has MPI; otherwise a cluster of one. Finalises MPI on destruction.
  Cluster(int& argc, char**& argv);
  ~Cluster();
  Cluster(const Cluster&) = delete;
  Cluster& operator=(const Cluster&) = delete;

  int rank() const { return rank_; }
  int size() const { return size_; }
  bool usesMpi() const { return mpi_; }
  /// True on every rank when `ok` is true on every rank (a collective: all ranks call it).
  bool allOk(bool ok) const;

  /// A finished probe: its index in the bake and its packed arrays (probe_bake.h pack()).
  struct Message {
    size_t probe = 0;
    std::vector<float> data;
  };
  /// Sends a probe to rank 0 (ranks > 0) without waiting for it to be received (the buffer is
  /// kept until it is; sends already received are released here).
  void send(size_t probe, std::vector<float> data);
  /// Waits until every send has been received (ranks > 0, before leaving).
  void finishSends();
  /// Rank 0: a probe of `floats` floats another rank has sent, once its data have arrived
  /// (never blocks: receives are posted and tested; the caller polls).
  std::optional<Message> receive(size_t floats);

  /// Trades one slice with each neighbouring rank: sends toLower to rank - 1 and toUpper to
  /// rank + 1, receives fromLower from rank - 1 and fromUpper from rank + 1 (each pair of
  /// spans as long as the neighbour's; empty where there is no neighbour). Blocks until done;
  /// every rank calls it.
  void exchangeWithNeighbours(std::span<const float> toLower, std::span<float> fromLower,
                              std::span<const float> toUpper, std::span<float> fromUpper);
  /// Every rank's `data` becomes rank `owner`'s (MPI_Bcast). Every rank calls it.
  void broadcast(std::span<float> data, int owner);

  /// Every rank but this one, with its pid when it runs on this process's host (0 otherwise),
  /// as rank 0's Watchdog watches them (apps/bake/watchdog.h). Empty without MPI.
  struct Peer {
    int rank = 0;
    long pid = 0;
  };
  const std::vector<Peer>& peers() const { return peers_; }

 private:
  struct Pending;  ///< a send in flight: its buffers and MPI requests
  struct Incoming;  ///< a receive in flight: its probe, buffer and request
  /// Gathers every rank's host and pid into peers_ (a collective, at start).
  void gatherPeers();
  int rank_ = 0, size_ = 1;
  bool mpi_ = false;
  std::vector<std::unique_ptr<Pending>> pending_;
  std::vector<std::unique_ptr<Incoming>> incoming_;
  std::vector<Peer> peers_;
};

/// Whether this build can join an MPI job.
bool builtWithMpi();

/// Runs step() -> exit status on every rank of `cluster`; rank 0 prints an escaping exception
/// as `program`'s one error line (common/program_main.h), the other ranks stay silent (they
/// meet the same input). A collective: true on every rank when step returned 0 on every rank.
template <typename Step>
bool together(Cluster& cluster, const char* program, Step&& step) {
  int status = 1;
  if (cluster.rank() == 0) {
    status = runReportingErrors(program, step);
  } else {
    try {
      status = step();
    } catch (...) {
      status = 1;
    }
  }
  return cluster.allOk(status == 0);
}

}  // namespace dpc
