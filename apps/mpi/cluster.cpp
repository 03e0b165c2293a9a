#include "apps/mpi/cluster.h"

#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <string>
#include <memory>
#include <vector>
#include <stdexcept>

#ifdef DPC_HAVE_MPI
#include <mpi.h>
#endif

namespace dpc {
namespace {

#ifdef DPC_HAVE_MPI
/// Tags: the probe index travels in a first message, its floats in a second; a slice sent
/// to the rank above, and one sent to the rank below.
constexpr int kTagProbe = 1;
constexpr int kTagData = 2;
constexpr int kTagUp = 3;
constexpr int kTagDown = 4;
#endif

bool startedByMpirun() {
  return std::getenv("OMPI_COMM_WORLD_SIZE") != nullptr || std::getenv("PMI_SIZE") != nullptr;
}

}  // namespace

#ifdef DPC_HAVE_MPI

namespace {

/// Throws std::runtime_error naming the call when an MPI call failed (MPI_ERRORS_RETURN).
void check(int rc, const char* call) {
  if (rc == MPI_SUCCESS) return;
  char text[MPI_MAX_ERROR_STRING];
  int n = 0;
  MPI_Error_string(rc, text, &n);
  throw std::runtime_error(std::string(call) + " failed: " + std::string(text, size_t(n)));
}

/// Host name length kept for telling ranks on this host from the others.
constexpr int kHostChars = 256;

}  // namespace

bool builtWithMpi() { return true; }

Cluster::Cluster(int& argc, char**& argv) {
  if (!startedByMpirun()) return;
  // Before MPI_Init, which reads it; a user's own choice (an existing variable) stands.
  ::setenv("OMPI_MCA_btl_vader_single_copy_mechanism", "none", 0);
  MPI_Init(&argc, &argv);
  mpi_ = true;
  MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
  gatherPeers();
}

void Cluster::gatherPeers() {
  char host[kHostChars] = {};
  ::gethostname(host, kHostChars - 1);
  std::vector<char> hosts(size_t(size_) * kHostChars);
  std::vector<long> pids(static_cast<size_t>(size_));
  long pid = long(::getpid());
  check(MPI_Allgather(host, kHostChars, MPI_CHAR, hosts.data(), kHostChars, MPI_CHAR,
                      MPI_COMM_WORLD), "MPI_Allgather");
  check(MPI_Allgather(&pid, 1, MPI_LONG, pids.data(), 1, MPI_LONG, MPI_COMM_WORLD),
        "MPI_Allgather");
  for (int r = 0; r < size_; ++r) {
    if (r == rank_) continue;
    const bool local = std::string(&hosts[size_t(r) * kHostChars]) == host;
    peers_.push_back({r, local ? pids[size_t(r)] : 0});
  }
}

Cluster::~Cluster() {
  if (!mpi_) return;
  finishSends();
  MPI_Finalize();
}

bool Cluster::allOk(bool ok) const {
  if (!mpi_) return ok;
  int mine = ok ? 1 : 0, all = 0;
  MPI_Allreduce(&mine, &all, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  return all == 1;
}

struct Cluster::Pending {
  uint64_t index = 0;
  std::vector<float> data;
  MPI_Request requests[2];
};

void Cluster::send(size_t probe, std::vector<float> data) {
  std::erase_if(pending_, [](const std::unique_ptr<Pending>& p) {
    int done = 0;
    MPI_Testall(2, p->requests, &done, MPI_STATUSES_IGNORE);
    return done != 0;
  });
  auto p = std::make_unique<Pending>();
  p->index = probe;
  p->data = std::move(data);
  check(MPI_Isend(&p->index, 1, MPI_UINT64_T, 0, kTagProbe, MPI_COMM_WORLD, &p->requests[0]),
        "MPI_Isend");
  check(MPI_Isend(p->data.data(), int(p->data.size()), MPI_FLOAT, 0, kTagData, MPI_COMM_WORLD,
                  &p->requests[1]),
        "MPI_Isend");
  pending_.push_back(std::move(p));
}

void Cluster::finishSends() {
  for (auto& p : pending_) MPI_Waitall(2, p->requests, MPI_STATUSES_IGNORE);
  pending_.clear();
}

struct Cluster::Incoming {
  Message message;
  MPI_Request request;
};

std::optional<Cluster::Message> Cluster::receive(size_t floats) {
  if (!mpi_) return std::nullopt;
  // A probe's index arrives first (one small message, delivered eagerly); its floats' receive
  // is posted at once and completes while the caller bakes on.
  MPI_Status status;
  int flag = 0;
  check(MPI_Iprobe(MPI_ANY_SOURCE, kTagProbe, MPI_COMM_WORLD, &flag, &status), "MPI_Iprobe");
  if (flag) {
    uint64_t index = 0;
    check(MPI_Recv(&index, 1, MPI_UINT64_T, status.MPI_SOURCE, kTagProbe, MPI_COMM_WORLD,
                   MPI_STATUS_IGNORE), "MPI_Recv");
    auto in = std::make_unique<Incoming>();
    in->message = {size_t(index), std::vector<float>(floats)};
    // Messages of one source and tag match in order: this is the index's own data.
    check(MPI_Irecv(in->message.data.data(), int(floats), MPI_FLOAT, status.MPI_SOURCE,
                    kTagData, MPI_COMM_WORLD, &in->request), "MPI_Irecv");
    incoming_.push_back(std::move(in));
  }
  for (auto it = incoming_.begin(); it != incoming_.end(); ++it) {
    int done = 0;
    check(MPI_Test(&(*it)->request, &done, MPI_STATUS_IGNORE), "MPI_Test");
    if (!done) continue;
    Message m = std::move((*it)->message);
    incoming_.erase(it);
    return m;
  }
  return std::nullopt;
}

void Cluster::exchangeWithNeighbours(std::span<const float> toLower, std::span<float> fromLower,
                                     std::span<const float> toUpper, std::span<float> fromUpper) {
  if (!mpi_) return;
  const int below = rank_ > 0 ? rank_ - 1 : MPI_PROC_NULL;
  const int above = rank_ + 1 < size_ ? rank_ + 1 : MPI_PROC_NULL;
  check(MPI_Sendrecv(toUpper.data(), int(toUpper.size()), MPI_FLOAT, above, kTagUp,
                     fromLower.data(), int(fromLower.size()), MPI_FLOAT, below, kTagUp,
                     MPI_COMM_WORLD, MPI_STATUS_IGNORE), "MPI_Sendrecv");
  check(MPI_Sendrecv(toLower.data(), int(toLower.size()), MPI_FLOAT, below, kTagDown,
                     fromUpper.data(), int(fromUpper.size()), MPI_FLOAT, above, kTagDown,
                     MPI_COMM_WORLD, MPI_STATUS_IGNORE), "MPI_Sendrecv");
}

void Cluster::broadcast(std::span<float> data, int owner) {
  if (!mpi_) return;
  check(MPI_Bcast(data.data(), int(data.size()), MPI_FLOAT, owner, MPI_COMM_WORLD), "MPI_Bcast");
}

#else

bool builtWithMpi() { return false; }

Cluster::Cluster(int&, char**&) {
  if (startedByMpirun())
    throw std::runtime_error("started by mpirun, but this program was built without MPI");
}
struct Cluster::Pending {};
struct Cluster::Incoming {};
Cluster::~Cluster() = default;
bool Cluster::allOk(bool ok) const { return ok; }
void Cluster::send(size_t, std::vector<float>) {}
void Cluster::finishSends() {}
std::optional<Cluster::Message> Cluster::receive(size_t) { return std::nullopt; }
void Cluster::exchangeWithNeighbours(std::span<const float>, std::span<float>,
                                     std::span<const float>, std::span<float>) {}
void Cluster::broadcast(std::span<float>, int) {}

#endif

}  // namespace dpc
