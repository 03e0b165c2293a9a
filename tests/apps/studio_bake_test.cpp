// dpc studio's /api/bake document (apps/studio/studio_json.h bakeJson) and the board's bake:
// each value lands at [probe][source][row][parameter] with STI in the broadband row only;
// values that are not finite, STI in a band row and every value of a probe not done are null;
// the float32 values come back as the same floats. The board holds no bake until one is set.
// /api/response says whether its response is the bake's or traced.
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>

#include "apps/studio/studio_json.h"

using namespace dpc;
using namespace dpc::studio;
using nlohmann::json;

namespace {

constexpr size_t kProbes = 3, kSources = 2, kParams = 7;

/// Value of (probe, source, row, parameter): distinct for every cell, not exact in decimal.
float cell(size_t p, size_t s, size_t row, size_t k) {
  return float(p) + 0.1f * float(s) + 0.01f * float(row) + 0.001f * float(k) + 1e-7f;
}

/// Probes 0 and 2 done, 1 not; T30 of probe 0, source 1, band 0 NaN; C80 of probe 2, source
/// 0, broadband +inf; STI of probe 2, source 1 NaN.
StudioBake sample() {
  StudioBake b;
  b.file = "b.h5";
  b.probes = {{1.f, 1.6f, 1.f}, {3.f, 1.6f, 1.f}, {5.f, 1.6f, 1.1f}};
  b.done = {1, 0, 1};
  b.sources = kSources;
  b.parameters = {"T20", "T30", "EDT", "C50", "C80", "D50", "G"};
  for (size_t p = 0; p < kProbes; ++p)
    for (size_t s = 0; s < kSources; ++s) {
      for (size_t row = 0; row < size_t(kBakeRows); ++row)
        for (size_t k = 0; k < kParams; ++k) {
          b.values.push_back(cell(p, s, row, k));
          b.ci95.push_back(cell(p, s, row, k) / 10.f);
        }
      b.sti.push_back(0.5f + 0.01f * float(p * kSources + s));
      b.stiCi95.push_back(0.02f);
    }
  auto at = [](size_t p, size_t s, size_t row, size_t k) {
    return ((p * kSources + s) * kBakeRows + row) * kParams + k;
  };
  b.values[at(0, 1, 0, 1)] = std::numeric_limits<float>::quiet_NaN();
  b.values[at(2, 0, kBakeRows - 1, 4)] = std::numeric_limits<float>::infinity();
  b.sti[2 * kSources + 1] = std::numeric_limits<float>::quiet_NaN();
  return b;
}

}  // namespace

TEST_CASE("studio bake document: layout, nulls and the same floats") {
  const StudioBake b = sample();
  const json j = json::parse(bakeJson(b));
  CHECK(j["file"] == "b.h5");
  CHECK(j["probes"].size() == 3 * kProbes);
  CHECK(j["probes"][8].get<float>() == 1.1f);
  CHECK(j["done"] == json::array({1, 0, 1}));
  CHECK(j["sources"] == kSources);
  REQUIRE(j["bands"].size() == size_t(kBakeRows));
  CHECK(j["bands"][4] == 1000.0);
  CHECK(j["bands"][kBakeRows - 1] == "broadband");
  CHECK(j["parameters"] == json::array({"T20", "T30", "EDT", "C50", "C80", "D50", "G", "STI"}));
  const size_t K = kParams + 1;
  REQUIRE(j["values"].size() == kProbes * kSources * kBakeRows * K);
  REQUIRE(j["ci95"].size() == j["values"].size());
  size_t nulls = 0;
  for (size_t p = 0; p < kProbes; ++p)
    for (size_t s = 0; s < kSources; ++s)
      for (size_t row = 0; row < size_t(kBakeRows); ++row)
        for (size_t k = 0; k < K; ++k) {
          const size_t i = ((p * kSources + s) * kBakeRows + row) * K + k;
          const json& v = j["values"][i];
          const bool broadband = row + 1 == size_t(kBakeRows);
          const float want = k < kParams ? b.values[((p * kSources + s) * kBakeRows + row) * kParams + k]
                                         : b.sti[p * kSources + s];
          const bool null = !b.done[p] || (k == kParams && !broadband) || !std::isfinite(want);
          INFO("probe " << p << " source " << s << " row " << row << " parameter " << k);
          CHECK(v.is_null() == null);
          if (!null) CHECK(v.get<float>() == want);  // parsed back to the very same float
          nulls += v.is_null();
        }
  // Probe 1 whole (2 x 9 x 8), STI outside broadband in probes 0 and 2 (2 x 2 x 8), T30 NaN,
  // C80 inf and STI NaN.
  CHECK(nulls == 144 + 32 + 3);
  CHECK(j["ci95"][((0 * kSources + 0) * kBakeRows + 8) * K + 7].get<float>() == 0.02f);
}

TEST_CASE("studio board: no bake until one is set, and the scene names it") {
  StudioBoard board;
  CHECK(board.bake() == nullptr);
  board.setBake(bakeJson(sample()));
  REQUIRE(board.bake() != nullptr);
  CHECK(json::parse(*board.bake())["sources"] == kSources);
  SceneDesc scene;
  scene.path = "s.json";
  CHECK(json::parse(sceneJson(scene))["bake"].is_null());
  CHECK(json::parse(sceneJson(scene, "b.h5"))["bake"] == "b.h5");
}

// The decay panel's document says where its response comes from (a pair played from the
// bake is not traced; its response is the bake's) and carries each band's bins unchanged.
TEST_CASE("studio response document: the response's origin and its bins per band") {
  StudioFrame f;
  f.frame = 7;
  f.binSeconds = 1e-3;
  f.energy.assign(3, Bands(0.f));
  f.energy[1][4] = 0.1f;
  f.energy[2][7] = 3e-9f;
  json j = json::parse(responseJson(f));
  CHECK(j["origin"] == "traced");
  CHECK(j["frame"] == 7);
  REQUIRE(j["bands"].size() == size_t(kNumBands));
  CHECK(j["bands"][4][1].get<float>() == 0.1f);
  CHECK(j["bands"][7][2].get<float>() == 3e-9f);
  CHECK(j["bands"][0].size() == 3);
  f.fromBake = true;
  j = json::parse(responseJson(f));
  CHECK(j["origin"] == "bake");
}
