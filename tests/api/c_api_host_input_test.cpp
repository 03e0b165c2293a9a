// dpc_engine_process with host inputs: the source's gain_db applies to them as to a scene's own
// signal, and a sample that cannot be a dry signal (not finite, beyond +-1e6) plays as 0 and is
// counted instead of filling the convolution's history (which silenced the output for the IR's
// length: 2.08 s of the box for one infinite sample).
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "dpc/dpc.h"
#include "tests/api/box_data.h"

namespace {

using dpc::test::BoxData;

struct HostRun {
  std::vector<float> left;  ///< the first output channel, 2 s at the engine's rate
  dpc_stats stats{};
};

/// The box with one host-input source at gain_db, a response traced, then 2 s of quiet white
/// noise (rms 0.01, seed fixed) played through dpc_engine_process with `spoil` applied to it.
HostRun playNoise(float gainDb, const std::vector<std::pair<size_t, float>>& spoil) {
  BoxData box;
  box.sources[0].gain_db = gainDb;
  dpc_engine_options o;
  dpc_engine_options_init(&o);
  o.host_inputs_only = 1;
  dpc_engine* e = nullptr;
  REQUIRE(dpc_engine_create_from_data(&box.data(), &o, &e) == DPC_OK);
  REQUIRE(dpc_engine_step(e) == DPC_OK);
  const int block = dpc_engine_block_size(e), channels = dpc_engine_output_channels(e);
  const size_t frames = size_t(2 * dpc_engine_sample_rate(e));
  std::vector<float> in(frames);
  std::mt19937 rng(7);
  std::normal_distribution<float> noise(0.f, 0.01f);
  for (float& x : in) x = noise(rng);
  for (const auto& [at, value] : spoil) in[at] = value;
  HostRun run;
  std::vector<float> out(size_t(block) * size_t(channels));
  std::vector<float*> outs;
  for (int c = 0; c < channels; ++c) outs.push_back(out.data() + size_t(c) * size_t(block));
  for (size_t n = 0; n + size_t(block) <= frames; n += size_t(block)) {
    const float* inputs[1] = {in.data() + n};
    REQUIRE(dpc_engine_process(e, inputs, outs.data(), block) == DPC_OK);
    run.left.insert(run.left.end(), out.begin(), out.begin() + block);
  }
  run.stats.struct_size = sizeof(dpc_stats);
  REQUIRE(dpc_engine_get_stats(e, &run.stats) == DPC_OK);
  dpc_engine_destroy(e);
  return run;
}

double energy(const std::vector<float>& x, size_t from) {
  double e = 0.0;
  for (size_t n = from; n < x.size(); ++n) e += double(x[n]) * x[n];
  return e;
}

}  // namespace

TEST_CASE("C API host inputs: unusable samples play as 0 and are counted", "[process]") {
  const HostRun clean = playNoise(0.f, {});
  const HostRun spoilt = playNoise(0.f, {{4800, std::numeric_limits<float>::quiet_NaN()},
                                         {9600, std::numeric_limits<float>::infinity()},
                                         {14400, std::numeric_limits<float>::max()},
                                         {19200, 2e6f}});
  CHECK(clean.stats.input_samples_replaced == 0);
  CHECK(spoilt.stats.input_samples_replaced == 4);
  CHECK(spoilt.stats.nan_blocks == 0);
  // The last second: the same noise less 4 of 96,000 samples (each about 1/96,000 of the
  // energy in), so within 0.1 % of the clean run; silenced, it would be 0.
  const size_t second = clean.left.size() / 2;
  REQUIRE(energy(clean.left, second) > 0.0);
  CHECK(energy(spoilt.left, second) == Approx(energy(clean.left, second)).epsilon(1e-3));
}

TEST_CASE("C API host inputs: the source's gain_db applies", "[process]") {
  const HostRun unity = playNoise(0.f, {});
  const HostRun quiet = playNoise(-20.f, {});
  // A linear system with the same response: -20 dB is an energy ratio of 0.01, up to float
  // rounding (1e-4 relative over 96,000 samples). Both stay far below the limiter's ceiling.
  CHECK(unity.stats.limited_frames == 0);
  REQUIRE(energy(unity.left, 0) > 0.0);
  CHECK(energy(quiet.left, 0) / energy(unity.left, 0) == Approx(0.01).epsilon(1e-4));
}
