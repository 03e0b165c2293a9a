// The materials library: named surfaces with octave-band absorption (63 Hz .. 8 kHz),
// scattering and the source of the numbers (materials/library.json, compiled into dpc_scene so
// that every program and binding sees the same table). Scenes name entries in their
// `materials` (docs/scene-format.md); materials/README.md says where the values come from and
// how untabulated bands and scattering are filled in.
//
// Any thread: the table is parsed once, on first use, under the C++ static-initialisation
// guarantee; the returned references stay valid for the program's life.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "scene/scene.h"

namespace dpc {

/// The file the table is compiled from, relative to the source tree (named by errors).
inline constexpr const char* kMaterialLibraryFile = "materials/library.json";

struct LibraryMaterial {
  Material material;        ///< name, absorption and scattering per octave band, in [0, 1]
  std::string description;  ///< the surface in words (construction, thickness, mounting)
  std::string source;       ///< the citation: book, table, section; extrapolated bands named
};

/// Every entry, sorted by name. The first call parses the compiled-in JSON and allocates;
/// it throws InputError only if the shipped table breaks the scene limits (a build defect that
/// tests/scene/material_library_test.cpp catches).
const std::vector<LibraryMaterial>& materialLibrary();

/// The entry called `name`, or nullptr.
const LibraryMaterial* findLibraryMaterial(std::string_view name);

}  // namespace dpc
