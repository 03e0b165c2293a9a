// The shipped shoebox names its materials from the library (materials/library.json); rendered
// offline, it equals the same scene with the values typed inline, bit for bit.
#include <catch2/catch.hpp>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "scene/scene.h"
#include "short_render.h"
#include "testing/temp_dir.h"

using namespace dpc;
using nlohmann::json;

namespace {

const std::string kScenes = std::string(DPC_SOURCE_DIR) + "/scenes";

/// The shoebox with its materials typed inline: the numbers of the Vorlaender table entries
/// that the shipped file names, with the walls' scattering override.
constexpr const char* kInlineMaterials = R"({
  "walls": { "absorption": [0.15, 0.15, 0.10, 0.06, 0.04, 0.04, 0.05, 0.05], "scattering": 0.2 },
  "floor": { "absorption": [0.03, 0.03, 0.09, 0.25, 0.31, 0.33, 0.44, 0.44], "scattering": 0.2 },
  "ceiling": { "absorption": [0.20, 0.20, 0.15, 0.10, 0.08, 0.04, 0.02, 0.02], "scattering": 0.1 }
})";

}  // namespace

TEST_CASE("Shoebox from library names renders as with the values inline", "[materials]") {
  std::ifstream in(kScenes + "/shoebox.json");
  json scene = json::parse(in);
  REQUIRE(scene["materials"]["floor"].is_string());  // the shipped file uses library names
  scene["materials"] = json::parse(kInlineMaterials);
  scene["mesh"] = kScenes + "/" + scene["mesh"].get<std::string>();
  for (json& s : scene["sources"])
    if (s.contains("signal")) s["signal"] = kScenes + "/" + s["signal"].get<std::string>();
  test::TempDir dir("dpc_material_library_render");
  const std::string inlinePath = (dir.path() / "shoebox-inline.json").string();
  std::ofstream(inlinePath) << scene.dump(2);

  const OfflineListenerResult named =
      test::shortRender(loadScene(kScenes + "/shoebox.json"), 500, 0.5);
  const OfflineListenerResult typed = test::shortRender(loadScene(inlinePath), 500, 0.5);
  REQUIRE(named.output.channels.size() == typed.output.channels.size());
  REQUIRE(!named.output.channels[0].empty());
  CHECK(named.output.channels == typed.output.channels);  // sample for sample
  REQUIRE(named.lastIrs.size() == typed.lastIrs.size());
  CHECK(named.lastIrs == typed.lastIrs);
}
