#include "apps/bake/cluster.h"

#include <cstdint>
#include <cstdlib>
#include <memory>
#include <vector>
#include <stdexcept>

#ifdef DPC_HAVE_MPI
#include <mpi.h>
#endif

namespace dpc::bake {
namespace {

#ifdef DPC_HAVE_MPI
/// Tags: the probe index travels in a first message, its floats in a second.
constexpr int kTagProbe = 1;
constexpr int kTagData = 2;
#endif

bool startedByMpirun() {
  return std::getenv("OMPI_COMM_WORLD_SIZE") != nullptr || std::getenv("PMI_SIZE") != nullptr;
}

}  // namespace

#ifdef DPC_HAVE_MPI

bool builtWithMpi() { return true; }

Cluster::Cluster(int& argc, char**& argv) {
  if (!startedByMpirun()) return;
  MPI_Init(&argc, &argv);
  mpi_ = true;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
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
  MPI_Isend(&p->index, 1, MPI_UINT64_T, 0, kTagProbe, MPI_COMM_WORLD, &p->requests[0]);
  MPI_Isend(p->data.data(), int(p->data.size()), MPI_FLOAT, 0, kTagData, MPI_COMM_WORLD,
            &p->requests[1]);
  pending_.push_back(std::move(p));
}

void Cluster::finishSends() {
  for (auto& p : pending_) MPI_Waitall(2, p->requests, MPI_STATUSES_IGNORE);
  pending_.clear();
}

std::optional<Cluster::Message> Cluster::receive(size_t floats) const {
  if (!mpi_) return std::nullopt;
  MPI_Status status;
  int flag = 0;
  MPI_Iprobe(MPI_ANY_SOURCE, kTagProbe, MPI_COMM_WORLD, &flag, &status);
  if (!flag) return std::nullopt;
  uint64_t index = 0;
  MPI_Recv(&index, 1, MPI_UINT64_T, MPI_ANY_SOURCE, kTagProbe, MPI_COMM_WORLD, &status);
  Message m{size_t(index), std::vector<float>(floats)};
  MPI_Recv(m.data.data(), int(floats), MPI_FLOAT, status.MPI_SOURCE, kTagData, MPI_COMM_WORLD,
           MPI_STATUS_IGNORE);
  return m;
}

#else

bool builtWithMpi() { return false; }

Cluster::Cluster(int&, char**&) {
  if (startedByMpirun())
    throw std::runtime_error("started by mpirun, but this dpc-bake was built without MPI");
}
struct Cluster::Pending {};
Cluster::~Cluster() = default;
bool Cluster::allOk(bool ok) const { return ok; }
void Cluster::send(size_t, std::vector<float>) {}
void Cluster::finishSends() {}
std::optional<Cluster::Message> Cluster::receive(size_t) const { return std::nullopt; }

#endif

}  // namespace dpc::bake
