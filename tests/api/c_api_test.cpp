// The C API's contract (include/dpc/dpc.h): error codes and messages instead of exceptions,
// unsupported operations reported as such, process() output finite and counted.
#include <catch2/catch.hpp>
#include <cmath>
#include <string>
#include <vector>

#include "dpc/dpc.h"

TEST_CASE("C API: bad arguments and bad scene files give codes and a message naming the file") {
  dpc_engine* e = reinterpret_cast<dpc_engine*>(1);
  CHECK(dpc_engine_create_from_file(nullptr, &e) == DPC_ERR_INVALID_ARGUMENT);
  CHECK(e == nullptr);
  CHECK(dpc_engine_create_from_file("x.json", nullptr) == DPC_ERR_INVALID_ARGUMENT);
  CHECK(dpc_engine_create_from_file("/nonexistent/scene.json", &e) == DPC_ERR_INPUT);
  CHECK(e == nullptr);
  CHECK(std::string(dpc_last_error()).find("/nonexistent/scene.json") != std::string::npos);
  CHECK(dpc_engine_start(nullptr) == DPC_ERR_INVALID_ARGUMENT);
  dpc_engine_destroy(nullptr);
}

TEST_CASE("C API: shoebox engine processes finite blocks, counts unsupported calls") {
  dpc_engine* e = nullptr;
  REQUIRE(dpc_engine_create_from_file(DPC_SOURCE_DIR "/scenes/shoebox.json", &e) == DPC_OK);
  const int block = dpc_engine_block_size(e), channels = dpc_engine_output_channels(e);
  CHECK(dpc_engine_sample_rate(e) == 48000);
  CHECK(block == 512);
  CHECK(dpc_engine_source_count(e) == 1);
  CHECK(dpc_engine_set_source_position(e, 0, 1.f, 1.f, 1.f) == DPC_OK);
  CHECK(dpc_engine_set_source_position(e, 1, 1.f, 1.f, 1.f) == DPC_ERR_INVALID_ARGUMENT);
  CHECK(dpc_engine_set_source_position(e, 0, INFINITY, 1.f, 1.f) == DPC_ERR_INVALID_ARGUMENT);
  const float identity[4] = {0.f, 0.f, 0.f, 1.f};
  CHECK(dpc_engine_object_count(e) == 0);
  CHECK(dpc_engine_set_object_pose(e, 0, 0.f, 0.f, 0.f, identity[0], identity[1], identity[2],
                                   identity[3]) == DPC_ERR_INVALID_ARGUMENT);
  CHECK(dpc_engine_latency_frames(e) == block);
  CHECK(dpc_engine_set_listener(e, NAN, 1.6f, 1.5f, 0.f, 0.f) == DPC_ERR_INVALID_ARGUMENT);
  CHECK(dpc_engine_set_listener(e, 3.5f, 1.6f, 1.5f, 90.f, 0.f) == DPC_OK);

  std::vector<float> buffer(size_t(block) * channels, 1.f);
  std::vector<float*> outputs;
  for (int c = 0; c < channels; ++c) outputs.push_back(buffer.data() + size_t(c) * block);
  for (int b = 0; b < 8; ++b)
    CHECK(dpc_engine_process(e, nullptr, outputs.data(), block) == DPC_OK);
  for (float v : buffer) REQUIRE(std::isfinite(v));
  // Other callback sizes are adapted (two half blocks make one engine block); sizes outside
  // 1..8192 render nothing and are counted.
  CHECK(dpc_engine_process(e, nullptr, outputs.data(), block / 2) == DPC_OK);
  CHECK(dpc_engine_process(e, nullptr, outputs.data(), block / 2) == DPC_OK);
  CHECK(dpc_engine_process(e, nullptr, outputs.data(), 0) == DPC_ERR_INVALID_ARGUMENT);
  CHECK(dpc_engine_process(e, nullptr, outputs.data(), 8193) == DPC_ERR_INVALID_ARGUMENT);
  dpc_stats s{};
  REQUIRE(dpc_engine_get_stats(e, &s) == DPC_OK);
  CHECK(s.blocks == 9);
  CHECK(s.rejected_callbacks == 2);
  CHECK(s.cache_budget_bytes == 0);  // no propagation frame has run yet
  CHECK(dpc_engine_start(e) == DPC_OK);
  CHECK(dpc_engine_stop(e) == DPC_OK);
  dpc_engine_destroy(e);
}
