// Golden checksums of energy responses computed by the engine before exact specular paths
// existed (same compiler and flags, x86-64): with exact_order 0 the engine must
// reproduce them bit for bit. A compiler change may change the float rounding and so these
// values, and so does the CPU's instruction set (Embree's kernels; see the test);
// scripts/render-all.sh against a reference build is then the check.
#include <catch2/catch.hpp>
#include <cstdint>
#include <cstdio>
#include <cstring>

#include "engine/simulation.h"
#include "testing/test_scenes.h"

using namespace dpc;

namespace {

/// FNV-1a over the bytes of every bin of an energy response.
uint64_t checksum(const EnergyResponse& er, uint64_t h = 0xcbf29ce484222325ULL) {
  const auto* p = reinterpret_cast<const unsigned char*>(er.bins().data());
  for (size_t i = 0; i < er.binCount() * sizeof(Bands); ++i) h = (h ^ p[i]) * 0x100000001b3ULL;
  return h;
}

/// Three frames of a two-listener shoebox and of the two rooms with a moving door, every
/// pair's response folded into one checksum.
uint64_t goldenRun(Estimator estimator) {
  uint64_t h = 0xcbf29ce484222325ULL;
  SceneDesc box = test::makeShoebox({10, 3, 7}, Bands(0.1f), 0.5f, {2, 1.5f, 2}, {7, 1.6f, 5});
  box.propagation.estimator = estimator;
  box.propagation.raysPerFrame = 2048;
  box.propagation.maxOrder = 40;
  box.propagation.exactOrder = 0;
  Simulation a(box);
  const ListenerSphere ls[2] = {{{7, 1.6f, 5}, 0.5f}, {{4, 1.2f, 1.5f}, 0.5f}};
  for (int f = 0; f < 3; ++f) {
    a.runFrame(std::span<const ListenerSphere>(ls, 2), {glm::vec3(2 + 0.3f * f, 1.5f, 2)});
    h = checksum(a.result(0, 0).energy, h);
    h = checksum(a.result(0, 1).energy, h);
  }
  SceneDesc rooms = test::twoRooms(DpcWeighting::kWindow, 0.5f);
  rooms.propagation.estimator = estimator;
  rooms.propagation.raysPerFrame = 2048;
  rooms.propagation.exactOrder = 0;
  // Edge diffraction adds to the direct sound alone, outside these bins; with it on, the door
  // leaf's reflection-based scattering (engine/reflection_scattering.h), which came after these
  // checksums, would steer its rays.
  rooms.propagation.diffraction = false;
  Simulation b(rooms);
  for (int f = 0; f < 3; ++f) {
    FrameInputs in = b.inputsAt(rooms.listeners[0].position);
    in.objectPoses = {f == 1 ? test::kDoorOpen : test::kDoorShut};
    b.runFrame(in);
    h = checksum(b.result(0).energy, h);
  }
  return h;
}

}  // namespace

TEST_CASE("exact_order 0 reproduces the engine's energy responses bit for bit", "[specular]") {
  const uint64_t pt = goldenRun(Estimator::kPathTracing);
  const uint64_t dpc = goldenRun(Estimator::kDpc);
  std::printf("golden checksums: path tracing %016llx, dpc %016llx\n", (unsigned long long)pt,
              (unsigned long long)dpc);
  // Embree picks its intersection kernels by the CPU's instruction set, and their float
  // rounding differs: the AVX-512 pair is the engine's from before exact paths existed; the
  // AVX2 pair was recorded on an AVX2-only CPU with exact_order 0 (a guard against change
  // from then on, not a check against the old engine).
  const bool avx512 = __builtin_cpu_supports("avx512f");
  INFO((avx512 ? "AVX-512" : "no AVX-512") << " CPU");
  CHECK(pt == (avx512 ? 0x98beb484ba7b5305ULL : 0x1771f34d55be9db6ULL));
  CHECK(dpc == (avx512 ? 0x95c1beff2ef9fc42ULL : 0x1317d4036575b8ffULL));
}
