// The materials library (materials/library.json, scene/material_library.h): every entry within
// the scene limits and citing a source, and scenes naming entries (plain or with overrides)
// loading the same numbers as typed inline.
#include "scene/material_library.h"
#include "scene/transmission.h"

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <string>

#include "scene/limits.h"
#include "scene_fixture.h"

using namespace dpc;
using dpc::test::Fixture;
using nlohmann::json;

namespace {

bool sameBits(const Bands& a, const Bands& b) {
  for (int i = 0; i < kNumBands; ++i) {
    const float x = a[i], y = b[i];
    if (std::memcmp(&x, &y, sizeof(float)) != 0) return false;
  }
  return true;
}

const Material& materialNamed(const SceneDesc& s, const std::string& name) {
  for (const Material& m : s.materials)
    if (m.name == name) return m;
  FAIL("no material " << name);
  return s.materials.front();
}

}  // namespace

TEST_CASE("Every library entry is within the limits, described and cited", "[materials]") {
  const auto& library = materialLibrary();
  REQUIRE(library.size() >= 40);
  const Limit& absorption = limitOf("materials.*.absorption");
  const Limit& scattering = limitOf("materials.*.scattering");
  for (size_t i = 0; i < library.size(); ++i) {
    const LibraryMaterial& e = library[i];
    INFO(e.material.name);
    if (i > 0) CHECK(library[i - 1].material.name < e.material.name);  // sorted, unique
    CHECK(!e.description.empty());
    // A citation names a published work and says how the 63 Hz band, which the tables
    // rarely give, was obtained.
    CHECK(e.source.find("Springer") != std::string::npos);
    CHECK(e.source.find("63 Hz") != std::string::npos);
    CHECK(e.source.find("scattering") != std::string::npos);
    const Bands tau = transmittanceOf(e.material.transmissionLossDb);
    for (int b = 0; b < kNumBands; ++b) {
      CHECK(withinLimit(absorption, e.material.absorption[b]));
      CHECK(withinLimit(scattering, e.material.scattering[b]));
      // Opaque, or a transmission loss within its limit that transmits no more than alpha.
      const float r = e.material.transmissionLossDb[b];
      CHECK((std::isinf(r) || withinLimit(limitOf("materials.*.transmission_loss_db"), r)));
      CHECK(tau[b] <= e.material.absorption[b]);
    }
    CHECK(findLibraryMaterial(e.material.name) == &e);
  }
  CHECK(findLibraryMaterial("no_such_surface") == nullptr);
}

TEST_CASE("A library name loads the entry's numbers bit for bit", "[materials]") {
  const LibraryMaterial& entry = *findLibraryMaterial("plasterboard_on_frame");
  Fixture f;
  f.scene["materials"]["walls"] = "plasterboard_on_frame";
  const SceneDesc named = f.load();
  // The same values typed inline, as the table prints them.
  f.scene["materials"]["walls"] = json::parse(
      R"({ "absorption": [0.15, 0.15, 0.10, 0.06, 0.04, 0.04, 0.05, 0.05], "scattering": 0.1 })");
  const SceneDesc inline_ = f.load();
  const Material& a = materialNamed(named, "walls");
  const Material& b = materialNamed(inline_, "walls");
  CHECK(sameBits(a.absorption, entry.material.absorption));
  CHECK(sameBits(a.absorption, b.absorption));
  CHECK(sameBits(a.scattering, b.scattering));
}

TEST_CASE("Fields next to \"library\" override the entry's", "[materials]") {
  const LibraryMaterial& entry = *findLibraryMaterial("carpet_cotton");
  Fixture f;
  f.scene["materials"]["floor"] = json::parse(R"({ "library": "carpet_cotton", "scattering": 0.7,
                                                   "source": "the scene's own note" })");
  const SceneDesc first = f.load();  // the material below refers into it
  const Material& m = materialNamed(first, "floor");
  CHECK(sameBits(m.absorption, entry.material.absorption));
  CHECK(sameBits(m.scattering, Bands(0.7f)));
  f.scene["materials"]["floor"] =
      json::parse(R"({ "library": "carpet_cotton", "absorption": 0.4 })");
  const SceneDesc second = f.load();
  const Material& n = materialNamed(second, "floor");
  CHECK(sameBits(n.absorption, Bands(0.4f)));
  CHECK(sameBits(n.scattering, entry.material.scattering));
}

TEST_CASE("Unknown library names and bad overrides name the file and the field", "[materials]") {
  Fixture f;
  f.scene["materials"]["walls"] = "plasterbord";
  std::string e = f.error();
  CHECK(e.find("scene.json: materials.walls: \"plasterbord\" is not in the materials library") !=
        std::string::npos);
  CHECK(e.find("--list-materials") != std::string::npos);
  f.scene["materials"]["walls"] = json::parse(R"({ "library": "nope" })");
  CHECK(f.error().find("materials.walls.library: \"nope\" is not in") != std::string::npos);
  f.scene["materials"]["walls"] = json::parse(R"({ "library": "glass_3mm", "scattering": 1.5 })");
  CHECK(f.error().find("materials.walls.scattering: 1.5") != std::string::npos);
  f.scene["materials"]["walls"] = json::parse(R"({ "library": 3 })");
  CHECK(f.error().find("materials.walls.library: expected a string") != std::string::npos);
  f.scene["materials"]["walls"] = json::parse(R"({ "scattering": 0.3 })");
  CHECK(f.error().find("materials.walls.absorption: missing") != std::string::npos);
  CHECK(std::count(e.begin(), e.end(), '\n') == 0);
}
