// An arrival whose delay moves across the non-uniform convolver's level boundaries, one IR set
// per "frame" (a source receding or approaching): the output keeps its level. Oracle: a unit
// impulse at delay d convolved with a unit sine is a unit sine, whatever d; the convolver's
// output amplitude is measured by quadrature demodulation over whole periods of the tone.
//
// Bounds (nonuniform_convolver.h, "Overlapping levels"): while the levels have not all taken
// the newest set, level l plays a newer set than level l+1. The sets in use are at most
// S = ceil(3 m_{l+1} / F) + 1 apart (level l+1 finishes its crossfade at most 3 m_{l+1} blocks
// after a set arrives; a set every F blocks), so their delays lie within S d of each other (d
// the delay step). Across the shared zone of Z_l samples a set's share changes by at most
// S d / Z_l, so the shares summed over the sets in use lie within 1 -+ S d / Z_l, and the
// phasors of delays S d apart add to at least cos(w S d / 2) of their sum: the amplitude lies
// in [(1 - S d / Z_l) cos(w S d / 2), 1 + S d / Z_l]. The instrument: a level switches sets
// within one block, so the phase may jump inside a window; the demodulation's double-frequency
// term then no longer cancels and reads up to |jump| / (2 pi W) off over a window of W periods
// (the sum of e^{-2iwt} over part of a period is at most 1 / sin w ~ P / (2 pi)). Two levels
// carry the arrival, each jumping by at most w S d: 2 w S d / (2 pi W) either way, W = 4.
// With the levels meeting at a hard
// boundary (overlap 0) the arrival is lost for a while (receding) or played twice
// (approaching), which the same bounds catch.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <memory>
#include <vector>

#include "audio/nonuniform_convolver.h"

using namespace dpc::audio;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kBlock = 128;
constexpr int kPeriod = 480;     // the tone's period, samples (100 Hz at 48 kHz)
constexpr int kWindowPeriods = 4;  // W: periods per amplitude measurement
constexpr int kSetEvery = 8;     // F: blocks between IR sets
constexpr size_t kIrSamples = 21000;

struct Envelope {
  double lowest = 1e9, highest = 0.0;
  size_t lowestAt = 0, highestAt = 0;  ///< output sample where the period begins
};

/// Renders a unit sine through the convolver while a unit impulse's delay steps from `from`
/// toward `to` by `step` samples every kSetEvery blocks, and measures the output amplitude in
/// windows of kWindowPeriods periods, one period apart, once the first arrival has sounded.
Envelope renderMovingArrival(int overlap, size_t from, size_t to, size_t step) {
  NonUniformLayout layout(kBlock, kIrSamples, NonUniformLayout::kDefaultMaxPartition,
                          ConvolverLayout::Planning::kEstimate, overlap);
  NonUniformConvolver conv(layout, 1, 1);
  // Two sets alternate: a set is lent only while the convolver no longer holds it.
  std::vector<std::unique_ptr<NonUniformIrSet>> pool;
  std::vector<NonUniformIrSet*> free;
  std::vector<float> ir(kIrSamples, 0.0f);
  const auto lend = [&](size_t delay) {
    while (const NonUniformIrSet* r = conv.takeRetired())
      free.push_back(const_cast<NonUniformIrSet*>(r));
    if (free.empty()) {
      pool.push_back(std::make_unique<NonUniformIrSet>(layout, 1, 1));
      free.push_back(pool.back().get());
    }
    NonUniformIrSet* set = free.back();
    free.pop_back();
    std::fill(ir.begin(), ir.end(), 0.0f);
    ir[delay] = 1.0f;
    const float* p = ir.data();
    set->prepare(0, &p, ir.size());
    REQUIRE(conv.setNextIr(set));
  };
  const size_t sets = (std::max(from, to) - std::min(from, to)) / step + 1;
  // After the last set, as long again as the slowest level needs to take it.
  const size_t blocks = sets * kSetEvery + 4 * size_t(layout.level(layout.numLevels() - 1).period);
  std::vector<float> in(kBlock), out(blocks * kBlock);
  for (size_t k = 0; k < blocks; ++k) {
    if (k % kSetEvery == 0 && k / kSetEvery < sets) {
      const size_t j = k / kSetEvery;
      lend(from < to ? from + j * step : from - j * step);
    }
    for (int n = 0; n < kBlock; ++n)
      in[size_t(n)] = float(std::sin(2.0 * kPi * double(k * kBlock + size_t(n)) / kPeriod));
    const float* ip = in.data();
    float* op = out.data() + k * kBlock;
    conv.process(&ip, &op);
  }
  Envelope e;
  const size_t window = size_t(kWindowPeriods) * kPeriod;
  for (size_t t0 = from + kPeriod; t0 + window <= out.size(); t0 += kPeriod) {
    double i = 0.0, q = 0.0;
    for (size_t t = t0; t < t0 + window; ++t) {
      const double phase = 2.0 * kPi * double(t) / kPeriod;
      i += out[t] * std::sin(phase);
      q += out[t] * std::cos(phase);
    }
    const double amplitude = 2.0 * std::hypot(i, q) / double(window);
    if (amplitude < e.lowest) e.lowest = amplitude, e.lowestAt = t0;
    if (amplitude > e.highest) e.highest = amplitude, e.highestAt = t0;
  }
  return e;
}

struct Crossing {
  size_t from, to, step;
  int nextPeriod;  ///< m_{l+1} of the boundary crossed
  size_t zone;     ///< Z_l = 2 N_l (the default overlap)
};

}  // namespace

TEST_CASE("An arrival moving across a level boundary keeps its level", "[convolver][heavy]") {
  // B = 128: boundaries at 768 (level 0 | 1), 3840 (1 | 2) and 16128 samples (2 | 3).
  const Crossing crossings[] = {{600, 1200, 2, 4, 256},
                                {3600, 5100, 2, 16, 1024},
                                {15900, 20500, 2, 64, 4096}};
  for (const Crossing& c : crossings) {
    const double s = std::ceil(3.0 * c.nextPeriod / kSetEvery) + 1.0;
    const double spread = s * double(c.step);
    const double held = spread / double(c.zone);
    const double jumps = 2.0 * (2.0 * kPi * spread / kPeriod) / (2.0 * kPi * kWindowPeriods);
    const double lower = (1.0 - held) * std::cos(kPi * spread / kPeriod) - jumps;
    const double upper = 1.0 + held + jumps;
    for (const bool receding : {true, false}) {
      const size_t from = receding ? c.from : c.to, to = receding ? c.to : c.from;
      const Envelope e = renderMovingArrival(NonUniformLayout::kDefaultOverlap, from, to, c.step);
      INFO("delay " << from << " -> " << to << ": amplitude " << e.lowest << " (at sample "
                    << e.lowestAt << ") .. " << e.highest << " (at " << e.highestAt << "), bounds "
                    << lower << " .. " << upper);
      CHECK(e.lowest >= lower);
      CHECK(e.highest <= upper);
      // The same motion across a hard boundary: lost, or played twice, for a while.
      const Envelope hard = renderMovingArrival(0, from, to, c.step);
      INFO("hard boundary: amplitude " << hard.lowest << " .. " << hard.highest);
      CHECK((hard.lowest < lower || hard.highest > upper));
    }
  }
}
