#include "scene/material_library.h"

#include <algorithm>
#include <nlohmann/json.hpp>

#include "common/input_error.h"
#include "scene/json_reader.h"
#include "scene/material_json.h"

namespace dpc {

// The text of materials/library.json (generated: scene/material_library_data.cpp.in).
extern const char* const kMaterialLibraryJson;

namespace {

using nlohmann::json;

/// One entry: every field required, so that no library value is a silent default.
LibraryMaterial readEntry(const JsonReader& r, const json& v, const std::string& name) {
  const std::string field = "materials." + name;
  r.expectObject(v, field);
  r.checkKeys(v, field,
              {"description", "absorption", "scattering", "transmission_loss_db", "source"});
  LibraryMaterial e;
  e.material.name = name;
  e.description = r.string(r.require(v, field, "description"), join(field, "description"));
  e.material.absorption = readBands(r, r.require(v, field, "absorption"), join(field, "absorption"),
                                    "materials.*.absorption");
  e.material.scattering = readBands(r, r.require(v, field, "scattering"), join(field, "scattering"),
                                    "materials.*.scattering");
  readTransmission(r, v, field, e.material);
  e.source = r.string(r.require(v, field, "source"), join(field, "source"));
  if (e.source.empty()) r.fail(join(field, "source"), "every entry must cite its source");
  return e;
}

std::vector<LibraryMaterial> parseLibrary() {
  const JsonReader r(kMaterialLibraryFile);
  json root;
  try {
    root = json::parse(kMaterialLibraryJson);
  } catch (const json::parse_error& e) {
    r.fail("", std::string("malformed JSON: ") + e.what());
  }
  r.expectObject(root, "");
  r.checkKeys(root, "", {"materials"});
  const json& mats = r.require(root, "", "materials");
  r.expectObject(mats, "materials");
  std::vector<LibraryMaterial> out;
  for (const auto& [name, value] : mats.items())
    if (name.empty() || name[0] != '_') out.push_back(readEntry(r, value, name));
  // nlohmann::json objects iterate in key order: already sorted by name.
  return out;
}

}  // namespace

const std::vector<LibraryMaterial>& materialLibrary() {
  static const std::vector<LibraryMaterial> library = parseLibrary();
  return library;
}

const LibraryMaterial* findLibraryMaterial(std::string_view name) {
  const auto& lib = materialLibrary();
  const auto it = std::lower_bound(lib.begin(), lib.end(), name,
                                   [](const auto& e, auto n) { return e.material.name < n; });
  return it != lib.end() && it->material.name == name ? &*it : nullptr;
}

}  // namespace dpc
