// Source directivity in scene files: the named patterns, per-band coefficients, the source's
// rotation (on the source and per keyframe), and the errors of bad directivity input.
#include "scene/directivity.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <string>

#include "common/input_error.h"
#include "scene/orientation.h"
#include "scene/scene.h"
#include "scene/trajectory.h"
#include "tests/scene/scene_fixture.h"

using namespace dpc;
using namespace dpc::test;
using Catch::Matchers::Contains;

namespace {

bool near(glm::vec3 a, glm::vec3 b) {
  return glm::length(a - b) < 1e-5f;
}

}  // namespace

TEST_CASE("Directivity patterns: gains and directivity factors", "[scene][directivity]") {
  // Eargle, The Microphone Book, ch. 5: cardioid sides -6 dB, rear null, Q = 3;
  // hypercardioid Q = 4; figure of eight Q = 3; omni Q = 1.
  const float cardioid = *directivityPatternA("cardioid");
  CHECK(10 * std::log10(directivityGain(cardioid, 0.f)) == Approx(-6.0206).margin(1e-3));
  CHECK(directivityGain(cardioid, -1.f) == 0.f);
  CHECK(1.f / directivityMeanGain(cardioid) == Approx(3.f));
  CHECK(1.f / directivityMeanGain(*directivityPatternA("hypercardioid")) == Approx(4.f));
  CHECK(1.f / directivityMeanGain(*directivityPatternA("figure8")) == Approx(3.f));
  CHECK(1.f / directivityMeanGain(0.f) == 1.f);
  CHECK_FALSE(directivityPatternA("shotgun"));
  // The weight's mean over the sphere is 1 (power preserved): integrate over cos theta, which
  // is uniform on [-1, 1] for uniform directions (midpoint rule, exact for a quadratic to 1e-6).
  Directivity d{Bands(0.63f)};
  double mean = 0;
  const int n = 2000;
  for (int i = 0; i < n; ++i) mean += directivityWeight(d, -1.f + 2.f * (i + 0.5f) / n)[3] / n;
  CHECK(mean == Approx(1.0).margin(1e-5));
}

TEST_CASE("A source's directivity and rotation are read from the scene file",
          "[scene][directivity]") {
  Fixture f;
  SECTION("default: omni, facing +x") {
    const SceneDesc s = f.load();
    CHECK(s.sources[0].directivity.omni());
    CHECK(near(sourceForward(sourceRotationAt(s.sources[0], 0.0)), {1, 0, 0}));
  }
  SECTION("a pattern name, turned 90 degrees about +y") {
    f.scene["sources"][0]["directivity"] = "cardioid";
    f.scene["sources"][0]["rotation"] = {0, std::sqrt(0.5), 0, std::sqrt(0.5)};
    const SceneDesc s = f.load();
    CHECK(s.sources[0].directivity.a == Bands(0.5f));
    CHECK(near(sourceForward(sourceRotationAt(s.sources[0], 0.0)), {0, 0, -1}));
  }
  SECTION("an object with a pattern, or per-band coefficients") {
    f.scene["sources"][0]["directivity"] = {{"pattern", "hypercardioid"}};
    CHECK(f.load().sources[0].directivity.a == Bands(0.75f));
    f.scene["sources"][0]["directivity"] = {{"a", {0, 0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6}}};
    const SceneDesc s = f.load();
    CHECK(s.sources[0].directivity.a[0] == 0.f);
    CHECK(s.sources[0].directivity.a[7] == 0.6f);
  }
  SECTION("keyframe rotations are slerped") {
    f.scene["sources"][0]["trajectory"] = json::parse(
        R"([{"t": 0, "position": [0.5, 0.5, 0.5], "rotation": [0, 0, 0, 1]},
            {"t": 2, "position": [0.5, 0.5, 0.5], "rotation": [0, 1, 0, 0]}])");
    const SceneDesc s = f.load();
    // Half of a half turn about +y: +x turns to -z.
    CHECK(near(sourceForward(sourceRotationAt(s.sources[0], 1.0)), {0, 0, -1}));
    CHECK(near(sourceForward(sourceRotationAt(s.sources[0], 5.0)), {-1, 0, 0}));
  }
}

TEST_CASE("Bad directivity input names the file and the field", "[scene][directivity]") {
  Fixture f;
  SECTION("unknown pattern") {
    f.scene["sources"][0]["directivity"] = "shotgun";
    CHECK_THAT(f.error(),
               Contains("scene.json: sources[0].directivity: \"shotgun\" is not one of"));
  }
  SECTION("unknown pattern inside an object") {
    f.scene["sources"][0]["directivity"] = {{"pattern", "omni2"}};
    CHECK_THAT(f.error(), Contains("sources[0].directivity.pattern: \"omni2\""));
  }
  SECTION("a outside [0, 1]") {
    f.scene["sources"][0]["directivity"] = {{"a", {0, 0, 0, 0, 0, 0, 0, 1.5}}};
    CHECK_THAT(f.error(), Contains("sources[0].directivity.a[7]: 1.5 is outside [0, 1]"));
  }
  SECTION("both pattern and a") {
    f.scene["sources"][0]["directivity"] = {{"a", 0.5}, {"pattern", "cardioid"}};
    CHECK_THAT(f.error(), Contains("sources[0].directivity: give exactly one of"));
  }
  SECTION("zero quaternion on the source") {
    f.scene["sources"][0]["rotation"] = {0, 0, 0, 0};
    CHECK_THAT(f.error(), Contains("sources[0].rotation: [0,0,0,0] has zero length"));
  }
  SECTION("a rotation on some keyframes only") {
    f.scene["sources"][0]["trajectory"] = json::parse(
        R"([{"t": 0, "position": [0.5, 0.5, 0.5], "rotation": [0, 0, 0, 1]},
            {"t": 2, "position": [0.5, 0.5, 0.5]}])");
    CHECK_THAT(f.error(),
               Contains("sources[0].trajectory[1].rotation: give \"rotation\" on every"));
  }
}
