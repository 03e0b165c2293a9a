// Materials out of JSON: the scene's `materials` entries (inline coefficients, a library name,
// or a library name with overrides) and the library's own entries (scene/material_library.h).
// Private to scene/. Formats: docs/scene-format.md "materials.NAME", materials/README.md.
//
// Control thread; allocates; throws InputError naming the file and the dotted field.
#pragma once

#include <string>

#include "scene/json_reader.h"
#include "scene/scene.h"

namespace dpc {

/// A per-band coefficient within the limit `limitField` (scene/limits.h): one number for every
/// octave band, or an array of exactly kNumBands numbers (63 Hz .. 8 kHz). Errors name `field`.
Bands readBands(const JsonReader& r, const nlohmann::json& v, const std::string& field,
                const char* limitField);

/// The optional `transmission_loss_db` of the material object v at `field` (dB, one number or
/// kNumBands; scene/transmission.h) into m; absent: m keeps its value (opaque by default).
void readTransmission(const JsonReader& r, const nlohmann::json& v, const std::string& field,
                      Material& m);

/// One scene material named `name` at `field` ("materials.walls"): an object with
/// `absorption` (required unless `library` is given), `scattering`, `source`, `library`; or a
/// string naming a library entry. Fields given next to `library` override the entry's.
Material readSceneMaterial(const JsonReader& r, const nlohmann::json& v, const std::string& name,
                           const std::string& field);

}  // namespace dpc
