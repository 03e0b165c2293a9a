// The limits table (scene/limits.h) against docs/scene-format.md, and the scene-file entry
// point fed every limit: each bound is accepted, one step beyond is refused with an error
// naming the field. Table-driven: a new limit is checked here without a new test.
#include "scene/limits.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>

#include "common/input_error.h"
#include "scene/scene.h"
#include "scene/validate.h"
#include "testing/temp_dir.h"
#include "tests/limit_probes.h"

using nlohmann::json;
using namespace dpc;

namespace {

const std::string kSourceDir = DPC_SOURCE_DIR;

std::string readText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream buf;
  buf << in.rdbuf();
  return buf.str();
}

/// The doc's minus signs (U+2212) as ASCII, so "[−200, 200]" reads as rangeText's "[-200, 200]".
std::string asciiMinus(std::string s) {
  std::string out;
  for (size_t at = 0, next; at < s.size(); at = next + 3) {
    next = std::min(s.find("\xE2\x88\x92", at), s.size());
    out.append(s, at, next - at);
    if (next < s.size()) out.push_back('-');
  }
  return out;
}

/// The doc section ("### `propagation`") and row key ("cache_tau") that document `field`.
std::pair<std::string, std::string> docPlace(const std::string& field) {
  const size_t dot = field.rfind('.');
  if (dot == std::string::npos)
    return field == "position" ? std::pair{"### `sources[i]`", "position"}
                               : std::pair{"### Top level", field};
  const std::string parent = field.substr(0, dot), key = field.substr(dot + 1);
  if (parent == "materials.*") return {"### `materials.NAME`", key};
  if (parent == "sources[]") return {"### `sources[i]`", key};
  if (parent == "sources[].directivity") return {"### `sources[i].directivity`", key};
  return {"### `" + parent + "`", key};
}

/// The table row of `key` in the doc section starting with `heading`; empty if none.
std::string docRow(const std::string& doc, const std::string& heading, const std::string& key) {
  const size_t start = doc.find("\n" + heading);
  if (start == std::string::npos) return "";
  const size_t end = doc.find("\n#", start + 1);
  const size_t row = doc.find("\n| `" + key + "` |", start);
  if (row == std::string::npos || row > end) return "";
  return doc.substr(row + 1, doc.find('\n', row + 1) - row - 1);
}

/// A valid scene (the shipped shoebox, with absolute paths) written to a temporary folder.
class SceneFile {
 public:
  SceneFile() : dir_("dpc_limits_test") {
    scene = json::parse(readText(kSourceDir + "/scenes/shoebox.json"));
    scene["mesh"] = kSourceDir + "/scenes/shoebox.obj";
    scene["sources"][0]["signal"] = kSourceDir + "/scenes/signals/speech.wav";
  }
  /// Loads the scene; returns the InputError's message, or nullopt when it loads.
  std::optional<std::string> loadError() const {
    const std::string path = (dir_.path() / "scene.json").string();
    std::ofstream(path) << scene.dump(2);
    try {
      loadScene(path);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::nullopt;
  }
  json scene;

 private:
  test::TempDir dir_;
};

json number(double x) {
  return x == std::floor(x) && std::abs(x) < 1e15 ? json(int64_t(x)) : json(x);
}

/// `count` entries of the array `field` ("sources", "listeners", "objects").
json entries(const std::string& field, size_t count) {
  json a = json::array();
  for (size_t i = 0; i < count; ++i) {
    std::string name(1, 'e');
    name.append(std::to_string(i));
    if (field == "sources") a.push_back({{"name", name}, {"position", {2, 1.6, 3.5}}});
    if (field == "listeners")
      a.push_back({{"name", name}, {"position", {8.5, 1.6, 1.5}}, {"radius", 0.5}});
    if (field == "objects")
      a.push_back({{"name", name},
                   {"mesh", kSourceDir + "/scenes/door.obj"},
                   {"trajectory", {{{"t", 0}, {"position", {5, 0, 3}}}}}});
  }
  return a;
}

/// Writes `value` where the limit `field` applies; returns the JSON path the error must
/// name, or nullopt when the value cannot be written (a negative count).
std::optional<std::string> setField(json& s, const std::string& field, double value) {
  const size_t dot = field.rfind('.');
  const std::string key = field.substr(dot + 1);
  if (field == "sources" || field == "listeners" || field == "objects") {
    if (value < 0) return std::nullopt;
    if (field == "listeners") s.erase("listener");
    if (field == "objects") s["materials"]["door"] = {{"absorption", 0.1}};
    s[field] = entries(field, size_t(value));
    return field;
  }
  // The wave band's crossover must lie below its maximum frequency, and its grid must be
  // fine enough for it: each is tried with the other at the value that admits all of it.
  if (field == "wave.crossover_hz") s["wave"]["max_frequency"] = 4000;
  if (field == "wave.grid_spacing") s["wave"]["max_frequency"] = 20;
  if (field == "position") {
    s["sources"][0]["position"][0] = number(value);
    return "sources[0].position[0]";
  }
  if (field.rfind("materials.*.", 0) == 0) {
    s["materials"]["walls"][key] = number(value);
    // Any R down to 0 dB (tau = 1) is valid only for a material absorbing all it transmits.
    if (key == "transmission_loss_db") s["materials"]["walls"]["absorption"] = 1;
    return "materials.walls." + key;
  }
  if (field == "sources[].directivity.a") {
    s["sources"][0]["directivity"] = {{"a", number(value)}};
    return "sources[0].directivity.a";
  }
  if (field.rfind("sources[].", 0) == 0) {
    s["sources"][0][key] = number(value);
    return "sources[0]." + key;
  }
  s[field.substr(0, dot)][key] = number(value);
  return field;
}

}  // namespace

TEST_CASE("docs/scene-format.md gives every limit's range as the table does", "[limits]") {
  const std::string doc = asciiMinus(readText(kSourceDir + "/docs/scene-format.md"));
  REQUIRE(!doc.empty());
  for (const Limit& l : limits()) {
    const auto [heading, key] = docPlace(std::string(l.field));
    INFO(l.field << " in " << heading);
    const std::string row = docRow(doc, heading, key);
    REQUIRE(!row.empty());
    INFO(row);
    CHECK(row.find(rangeText(l)) != std::string::npos);
  }
}

TEST_CASE("Limits table: ranges and messages", "[limits]") {
  CHECK(rangeText(limitOf("audio.sample_rate")) == "[16000, 192000]");
  CHECK(rangeText(limitOf("propagation.ir_length")) == "(0, 60]");
  CHECK(rangeText(limitOf("listener.radius")) == "(0, 1000000]");
  CHECK(rangeText(limitOf("propagation.patch_size")) == "> 0");
  CHECK(valueText(1.7f) == "1.7");
  CHECK(valueText(48000) == "48000");
  CHECK_THROWS_AS(limitOf("no.such.field"), std::logic_error);
  CHECK_THROWS_WITH(checkField("propagation.cache_tau", 4000, commandLineOrigin()),
                    "command line: --tau: 4000 is outside [0, 3600] s");
  CHECK_THROWS_WITH(checkField("audio.block_size", 512.5, Origin{"x.json", {}}),
                    "x.json: audio.block_size: 512.5 is not an integer");
  for (const Limit& l : limits()) {
    INFO(l.field);
    CHECK(!l.why.empty());
    CHECK(l.min < l.max);
  }
}

TEST_CASE("A float field is checked as single precision holds it", "[limits]") {
  const Origin flags = commandLineOrigin();
  CHECK(checkFloatField("propagation.cache_tau", 0.25, flags) == 0.25f);
  // 1e-300 rounds to 0, which for cache_tau means plain path tracing: refused, not switched.
  CHECK_THROWS_WITH(checkFloatField("propagation.cache_tau", 1e-300, flags),
                    "command line: --tau: 1e-300 rounds to 0 in single precision");
  // Out of range once rounded: the range is named too.
  CHECK_THROWS_WITH(checkFloatField("propagation.ir_length", 1e-300, flags),
                    Catch::Contains("rounds to 0 in single precision: 0 is outside (0, 60] s"));
  // No upper limit, but beyond what a float holds (the conversion would be undefined).
  CHECK_THROWS_WITH(
      checkFloatField("propagation.patch_size", 1e39, Origin{"x.json", {}}),
      "x.json: propagation.patch_size: 1e+39 is beyond single precision (at most 3.4e38 in "
      "magnitude)");
  CHECK_THROWS_WITH(checkFloatField("propagation.cache_memory_mb", std::nan(""), flags),
                    Catch::StartsWith("command line: --cache-memory-mb: "));
  // -0 is held as 0 (a sign that would print as "-0" in outputs).
  CHECK_FALSE(std::signbit(checkFloatField("propagation.cache_tau", -0.0, flags)));
}

TEST_CASE("Scene file: every limit is accepted at its bounds and refused beyond", "[limits]") {
  for (const Limit& l : limits()) {
    for (const test::LimitProbe& p : test::probesFor(l)) {
      SceneFile f;
      const auto path = setField(f.scene, std::string(l.field), p.value);
      if (!path) continue;
      INFO(l.field << " " << p.what << " = " << valueText(p.value) << " at " << *path);
      const std::optional<std::string> error = f.loadError();
      if (p.accepted) {
        CHECK(error.value_or("") == "");
      } else {
        REQUIRE(error.has_value());
        CHECK(error->find(": " + *path + ": ") != std::string::npos);
      }
    }
  }
}
