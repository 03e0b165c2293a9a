// CallbackAdapter (runtime/callback_adapter.h): any sequence of host call sizes delays the
// engine's blocks by exactly one block, inputs and outputs alike.
#include "runtime/callback_adapter.h"

#include <catch2/catch.hpp>
#include <random>
#include <vector>

using namespace dpc;

TEST_CASE("CallbackAdapter: random call sizes give a constant one-block latency", "[adapter]") {
  constexpr int kBlock = 64;
  CallbackAdapter adapter(kBlock, 1, 2);
  CHECK(adapter.latencyFrames() == kBlock);
  // Engine: output channel 0 = the block's host input, channel 1 = the block's index.
  int blocks = 0;
  auto engine = [&](const float* const* in, float* const* out) {
    REQUIRE(in != nullptr);
    for (int i = 0; i < kBlock; ++i) {
      out[0][i] = in[0][i];
      out[1][i] = float(blocks);
    }
    ++blocks;
    return blocks % 3 == 0;  // "swapped" every third block
  };
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> size(1, 300);
  std::vector<float> input, out0, out1;
  bool anySwap = false;
  while (input.size() < 20000) {
    const int n = size(rng);
    const size_t len = static_cast<size_t>(n);
    std::vector<float> in(len), o0(len), o1(len);
    for (int i = 0; i < n; ++i) in[size_t(i)] = float(input.size() + size_t(i) + 1);
    const float* inputs[1] = {in.data()};
    float* outputs[2] = {o0.data(), o1.data()};
    anySwap = adapter.run(inputs, outputs, n, engine) || anySwap;
    input.insert(input.end(), in.begin(), in.end());
    out0.insert(out0.end(), o0.begin(), o0.end());
    out1.insert(out1.end(), o1.begin(), o1.end());
  }
  CHECK(anySwap);
  CHECK(blocks == int(input.size()) / kBlock);
  bool delayed = true;
  for (size_t t = 0; t < out0.size(); ++t) {
    const float expect = t < kBlock ? 0.f : input[t - kBlock];
    const float block = t < kBlock ? 0.f : float(t / kBlock - 1);
    delayed = delayed && out0[t] == expect && out1[t] == block;
  }
  CHECK(delayed);
}

TEST_CASE("CallbackAdapter: without host inputs the engine gets none", "[adapter]") {
  CallbackAdapter adapter(16, 2, 1);
  std::vector<float> o(40);
  float* outputs[1] = {o.data()};
  int calls = 0;
  adapter.run(nullptr, outputs, 40, [&](const float* const* in, float* const* out) {
    CHECK(in == nullptr);
    std::fill(out[0], out[0] + 16, 1.f);
    ++calls;
    return false;
  });
  CHECK(calls == 2);
  CHECK(o[15] == 0.f);
  CHECK(o[16] == 1.f);
}
