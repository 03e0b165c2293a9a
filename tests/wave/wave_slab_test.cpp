// The wave solver's domain decomposition: processes stepping one slab of z slices each and
// trading edge slices every step give the IRs one process gives, bit for bit, for any number
// of processes. The processes here are threads joined by a barrier (the same SlabLink contract
// an MPI job meets; tests/wave/wave_mpi_test.sh runs dpc-wave under mpirun). The room has no
// symmetry to hide an error: a partition of another material, several receivers, one of them
// on a slab's edge for some process counts.
#include <barrier>
#include <catch2/catch.hpp>
#include <stdexcept>
#include <thread>

#include "engine/embree_tracer.h"
#include "engine/geometry.h"
#include "testing/test_scenes.h"
#include "wave/wave_band.h"

namespace dpc {
namespace {

/// What the processes share: a barrier and one mailbox per process.
struct Post {
  explicit Post(int n) : sync(n), down(size_t(n)), up(size_t(n)) {}
  std::barrier<> sync;
  std::vector<std::vector<float>> down, up;  ///< the slices each process sent down and up
  std::vector<float> shared;                 ///< a broadcast's data
};

/// A process of `post`; `trade` false: exchange() sends nothing (an edge never refreshed).
class ThreadLink final : public wave::SlabLink {
 public:
  ThreadLink(Post& post, int rank, int size, bool trade)
      : post_(post), rank_(rank), size_(size), trade_(trade) {}
  int rank() const override { return rank_; }
  int size() const override { return size_; }
  void exchange(std::span<const float> toLower, std::span<float> fromLower,
                std::span<const float> toUpper, std::span<float> fromUpper) override {
    post_.down[size_t(rank_)].assign(toLower.begin(), toLower.end());
    post_.up[size_t(rank_)].assign(toUpper.begin(), toUpper.end());
    post_.sync.arrive_and_wait();
    if (trade_ && !fromLower.empty()) std::ranges::copy(post_.up[size_t(rank_ - 1)], fromLower.begin());
    if (trade_ && !fromUpper.empty()) std::ranges::copy(post_.down[size_t(rank_ + 1)], fromUpper.begin());
    post_.sync.arrive_and_wait();
  }
  void broadcast(std::span<float> data, int owner) override {
    if (rank_ == owner) post_.shared.assign(data.begin(), data.end());
    post_.sync.arrive_and_wait();
    if (rank_ != owner) std::ranges::copy(post_.shared, data.begin());
    post_.sync.arrive_and_wait();
  }

 private:
  Post& post_;
  int rank_, size_;
  bool trade_;
};

const glm::vec3 kSource(0.7f, 1.1f, 0.9f);
const std::vector<wave::WavePoint> kReceivers{{{3.2f, 1.9f, 2.6f}, "a"},
                                              {{1.2f, 0.6f, 1.65f}, "b"},
                                              {{3.9f, 2.5f, 0.2f}, "c"}};

/// The IRs at kReceivers as each of `processes` threads returns them (one process: no link).
std::vector<std::vector<std::vector<float>>> run(int processes, bool trade = true) {
  const SceneDesc s = test::partitionedWaveBox();
  const Geometry geometry(s.mesh, s.materials, s.propagation.patchSize);
  const EmbreeTracer tracer(s.mesh);
  std::vector<std::vector<std::vector<float>>> irs(static_cast<size_t>(processes));
  Post post(processes);
  auto process = [&](int rank) {
    ThreadLink link(post, rank, processes, trade);
    wave::WaveBandOptions opt;
    opt.seconds = 0.15;
    if (processes > 1) opt.link = &link;
    irs[size_t(rank)] = wave::simulateWaveBand(s, tracer, geometry, {kSource, "source"},
                                               kReceivers, opt).irs;
  };
  std::vector<std::jthread> threads;
  for (int r = 0; r < processes; ++r) threads.emplace_back(process, r);
  return irs;
}

}  // namespace

TEST_CASE("Wave band by slabs: any number of processes gives one process's IRs, bit for bit",
          "[wave]") {
  const auto one = run(1).front();
  REQUIRE(one.size() == kReceivers.size());
  double energy = 0.0;
  for (float v : one[1]) energy += double(v) * v;
  REQUIRE(energy > 0.0);
  for (int processes : {2, 3, 7}) {
    INFO(processes << " processes");
    const auto shared = run(processes);
    for (size_t rank = 0; rank < shared.size(); ++rank) {
      INFO("process " << rank);
      CHECK(shared[rank] == one);  // every float equal: no tolerance
    }
  }
}

TEST_CASE("Wave band by slabs: the check sees edges left stale", "[wave]") {
  // The same run with exchange() trading nothing: the receivers must differ, or the case above
  // could not see a decomposition that ignores its neighbours.
  const auto one = run(1).front();
  const auto stale = run(3, false);
  CHECK(stale.front() != one);
}

TEST_CASE("Wave band by slabs: more processes than slices are refused", "[wave]") {
  wave::GridLayout layout;
  layout.count = {10, 10, 4};
  CHECK(wave::slabOf(layout, 3, 4).last == 5);
  CHECK(wave::slabOf(layout, 0, 4).first == 1);
  CHECK_THROWS_AS(wave::slabOf(layout, 0, 5), std::invalid_argument);
}

}  // namespace dpc
