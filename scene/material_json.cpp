#include "scene/material_json.h"

#include "scene/limits.h"
#include "scene/material_library.h"

namespace dpc {

using nlohmann::json;

Bands readBands(const JsonReader& r, const json& a, const std::string& field,
                const char* limitField) {
  Bands out;
  if (a.is_array()) {
    if (a.size() != size_t(kNumBands))
      r.fail(field, "expected " + std::to_string(kNumBands) +
                        " values (octave bands 63 Hz .. 8 kHz), got " + std::to_string(a.size()));
    for (int b = 0; b < kNumBands; ++b)
      out[b] = float(r.limited(a[size_t(b)], index(field, size_t(b)), limitField));
  } else if (a.is_number()) {
    out = Bands(float(r.limited(a, field, limitField)));
  } else {
    const Limit& limit = limitOf(limitField);
    r.fail(field, "expected a number or an array of " + std::to_string(kNumBands) +
                      " numbers in " + rangeText(limit) +
                      (limit.unit.empty() ? "" : " " + std::string(limit.unit)) + ", got " +
                      JsonReader::describe(a));
  }
  return out;
}

void readTransmission(const JsonReader& r, const json& v, const std::string& field, Material& m) {
  if (const json* t = JsonReader::find(v, "transmission_loss_db"))
    m.transmissionLossDb = readBands(r, *t, join(field, "transmission_loss_db"),
                                     "materials.*.transmission_loss_db");
}

namespace {

/// The library entry named by the string at `field`; the error lists nothing but points to
/// `dpc-demo --list-materials`, the library having dozens of names.
const LibraryMaterial& libraryEntry(const JsonReader& r, const json& v, const std::string& field) {
  const std::string name = r.string(v, field);
  const LibraryMaterial* entry = findLibraryMaterial(name);
  if (!entry)
    r.fail(field, inQuotes(name) + " is not in the materials library (" + kMaterialLibraryFile +
                      "; dpc-demo --list-materials prints its names)");
  return *entry;
}

}  // namespace

Material readSceneMaterial(const JsonReader& r, const json& v, const std::string& name,
                           const std::string& field) {
  Material m;
  if (v.is_string()) {
    m = libraryEntry(r, v, field).material;
    m.name = name;
    return m;
  }
  r.expectObject(v, field);
  r.checkKeys(v, field,
              {"library", "absorption", "scattering", "transmission_loss_db", "source"});
  const json* library = JsonReader::find(v, "library");
  if (library) m = libraryEntry(r, *library, join(field, "library")).material;
  m.name = name;
  const json* a = library ? JsonReader::find(v, "absorption") : &r.require(v, field, "absorption");
  if (a) m.absorption = readBands(r, *a, join(field, "absorption"), "materials.*.absorption");
  if (const json* s = JsonReader::find(v, "scattering"))
    m.scattering = readBands(r, *s, join(field, "scattering"), "materials.*.scattering");
  readTransmission(r, v, field, m);
  if (const json* s = JsonReader::find(v, "source")) r.string(*s, join(field, "source"));
  return m;
}

}  // namespace dpc
