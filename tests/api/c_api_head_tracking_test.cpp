// Head-tracked binaural through the C API (DPC_OUTPUT_AMBISONIC_BINAURAL): two output
// channels, (order + 1)^2 IR channels, and a listener pose that turns the heard field on the
// next audio block without a propagation frame in between.
#include <catch2/catch.hpp>
#include <cmath>
#include <string>
#include <vector>

#include "dpc/dpc.h"
#include "tests/api/box_data.h"

namespace {

/// Direct-sound energy per ear (left, right) for a unit impulse fed after one silent block
/// (the block in which the engine reads a new pose crossfades to the turned field): the first
/// 1.5 ms of the direct sound (the box's first reflection arrives later), after the engine's
/// latency and the HRIRs' onset delay (up to 1.5 ms in KEMAR).
std::vector<double> directEnergy(dpc_engine* e, double distanceMetres) {
  const int B = dpc_engine_block_size(e), fs = dpc_engine_sample_rate(e);
  {
    std::vector<float> zeros(size_t(B), 0.f), l(zeros), r(zeros);
    const float* inputs[1] = {zeros.data()};
    float* outputs[2] = {l.data(), r.data()};
    REQUIRE(dpc_engine_process(e, inputs, outputs, B) == DPC_OK);
  }
  const size_t latency = size_t(dpc_engine_latency_frames(e));
  const size_t direct = latency + size_t(distanceMetres / 343.0 * fs);
  const size_t end = direct + size_t(fs) * 3 / 1000;
  const size_t frames = size_t(B);
  std::vector<float> in(frames, 0.f), left(frames, 0.f), right(frames, 0.f);
  std::vector<double> energy(2, 0.0);
  in[0] = 1.f;
  for (size_t n = 0; n < end; n += size_t(B)) {
    const float* inputs[1] = {in.data()};
    float* outputs[2] = {left.data(), right.data()};
    REQUIRE(dpc_engine_process(e, inputs, outputs, B) == DPC_OK);
    in[0] = 0.f;
    for (size_t i = 0; i < size_t(B); ++i)
      if (n + i + 24 >= direct && n + i < end) {  // from 0.5 ms before the arrival
        energy[0] += double(left[i]) * left[i];
        energy[1] += double(right[i]) * right[i];
      }
  }
  // Let the IR ring out so that the next impulse meets silence.
  std::vector<float> zeros(size_t(B), 0.f);
  for (int k = 0; k < fs / B; ++k) {
    const float* inputs[1] = {zeros.data()};
    float* outputs[2] = {left.data(), right.data()};
    REQUIRE(dpc_engine_process(e, inputs, outputs, B) == DPC_OK);
  }
  return energy;
}

}  // namespace

TEST_CASE("C API: head-tracked binaural turns with the listener's pose, no frame needed",
          "[api][ambisonics]") {
  dpc::test::BoxData box;
  box.d.output = DPC_OUTPUT_AMBISONIC_BINAURAL;
  box.d.ambisonic_order = 3;
  box.d.ir_length = 0.5f;
  dpc_engine_options options;
  dpc_engine_options_init(&options);
  options.host_inputs_only = 1;
  dpc_engine* e = nullptr;
  REQUIRE(dpc_engine_create_from_data(&box.data(), &options, &e) == DPC_OK);
  CHECK(dpc_engine_output_channels(e) == 2);
  CHECK(dpc_engine_ir_channels(e) == 16);
  REQUIRE(dpc_engine_step(e) == DPC_OK);  // the one propagation frame of this test
  // The source stands 2 m along -x from the listener at (4, 1.5, 2). Facing +x (yaw 0) it is
  // behind: about equal ears. Yaw +90 faces -z, putting it on the left; -90 on the right.
  const double d = 2.0;
  std::vector<double> ahead = directEnergy(e, d);
  const auto ild = [](const std::vector<double>& x) { return 10.0 * std::log10(x[0] / x[1]); };
  INFO("ILD facing +x " << ild(ahead) << " dB");
  CHECK(std::abs(ild(ahead)) < 3.0);
  REQUIRE(dpc_engine_set_listener_pose(e, 0, 4.f, 1.5f, 2.f, 90.f, 0.f) == DPC_OK);
  const std::vector<double> left = directEnergy(e, d);
  REQUIRE(dpc_engine_set_listener_pose(e, 0, 4.f, 1.5f, 2.f, -90.f, 0.f) == DPC_OK);
  const std::vector<double> right = directEnergy(e, d);
  INFO("ILD turned left " << ild(left) << " dB, turned right " << ild(right) << " dB");
  // KEMAR's ILD of a source at 90 degrees is 8-10 dB broadband; order-3 decoding keeps > 5.
  CHECK(ild(left) > 5.0);
  CHECK(ild(right) < -5.0);
  // Facing -z with the source on the left, a roll of 90 degrees either way puts the source
  // straight above (roll -90: the left ear down) or below (+90) the head: the median plane,
  // about equal ears again, as behind. Rolled 45 degrees the source is still 45 degrees off
  // the median plane, on the left: lateral (KEMAR's ILD there is as large as at 90 degrees,
  // where the far ear's bright spot lowers it).
  REQUIRE(dpc_engine_set_listener_head_pose(e, 0, 4.f, 1.5f, 2.f, 90.f, 0.f, -90.f) == DPC_OK);
  const std::vector<double> above = directEnergy(e, d);
  REQUIRE(dpc_engine_set_listener_head_pose(e, 0, 4.f, 1.5f, 2.f, 90.f, 0.f, 90.f) == DPC_OK);
  const std::vector<double> below = directEnergy(e, d);
  REQUIRE(dpc_engine_set_listener_head_pose(e, 0, 4.f, 1.5f, 2.f, 90.f, 0.f, 45.f) == DPC_OK);
  const std::vector<double> half = directEnergy(e, d);
  INFO("ILD rolled -90 " << ild(above) << " dB, +90 " << ild(below) << " dB, +45 " << ild(half));
  CHECK(std::abs(ild(above)) < 3.0);
  CHECK(std::abs(ild(below)) < 3.0);
  CHECK(ild(half) > 5.0);
  CHECK(dpc_engine_set_listener_head_pose(e, 0, 4.f, 1.5f, 2.f, 90.f, 0.f, 181.f) ==
        DPC_ERR_INVALID_ARGUMENT);
  CHECK(std::string(dpc_last_error()).find("roll_degrees") != std::string::npos);
  dpc_stats stats;
  stats.struct_size = sizeof stats;
  REQUIRE(dpc_engine_get_stats(e, &stats) == DPC_OK);
  CHECK(stats.frames == 1);  // no propagation frame ran for the turns
  dpc_engine_destroy(e);
}

TEST_CASE("C API: AmbiX output renders (order + 1)^2 finite channels live", "[api][ambisonics]") {
  dpc::test::BoxData box;
  box.d.output = DPC_OUTPUT_AMBISONICS;
  box.d.ir_length = 0.3f;
  dpc_engine_options options;
  dpc_engine_options_init(&options);
  options.host_inputs_only = 1;
  options.ambisonic_order = 2;  // overrides the data's 3
  dpc_engine* e = nullptr;
  REQUIRE(dpc_engine_create_from_data(&box.data(), &options, &e) == DPC_OK);
  REQUIRE(dpc_engine_output_channels(e) == 9);
  CHECK(dpc_engine_ir_channels(e) == 9);
  REQUIRE(dpc_engine_step(e) == DPC_OK);
  const size_t B = size_t(dpc_engine_block_size(e));
  std::vector<std::vector<float>> out(9, std::vector<float>(B, 0.f));
  std::vector<float*> outs;
  for (auto& c : out) outs.push_back(c.data());
  std::vector<float> in(B, 0.f);
  in[0] = 1.f;
  std::vector<double> energy(9, 0.0);
  std::vector<float> w, x;  // W and X as played
  for (int k = 0; k < 8; ++k) {
    const float* inputs[1] = {in.data()};
    REQUIRE(dpc_engine_process(e, inputs, outs.data(), int(B)) == DPC_OK);
    in[0] = 0.f;
    for (size_t c = 0; c < 9; ++c)
      for (float v : out[c]) {
        REQUIRE(std::isfinite(v));
        energy[c] += double(v) * v;
      }
    w.insert(w.end(), out[0].begin(), out[0].end());
    x.insert(x.end(), out[3].begin(), out[3].end());
  }
  // The direct sound: the first sample of W above 0.4 of W's largest. The largest arrival is
  // the floor and ceiling images, coincident at 3.6 m (listener and source at mid-height):
  // together 2 x 2 / 3.6 = 1.1 times the direct sound at 2 m, so the direct sound clears 0.4.
  float peak = 0.f;
  for (float v : w) peak = std::max(peak, std::abs(v));
  size_t direct = 0;
  while (direct < w.size() && std::abs(w[direct]) <= 0.4f * peak) ++direct;
  REQUIRE(direct < w.size());
  // The source lies along -x from the listener. A plane wave from -x has, in ACN/SN3D,
  // X = W cos(azimuth) cos(elevation) = -W (azimuth 180 degrees): at the direct sound X is -W,
  // up to what overlaps it (the next arrival is 1.6 m, 4.7 ms, later: 1 %). Y (ACN 1, left)
  // carries only reflections, so less energy than X.
  CHECK(energy[0] > 0.0);
  CHECK(x[direct] == Approx(-w[direct]).epsilon(0.01));
  CHECK(energy[1] < energy[3]);
  dpc_engine_options bad;
  dpc_engine_options_init(&bad);
  bad.ambisonic_order = 8;
  dpc_engine* none = nullptr;
  CHECK(dpc_engine_create_from_data(&box.data(), &bad, &none) == DPC_ERR_INVALID_ARGUMENT);
  CHECK(none == nullptr);
  dpc_engine_destroy(e);
}
