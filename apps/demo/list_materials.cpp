#include "apps/demo/list_materials.h"

#include <cstdio>
#include <string>

#include "common/bands.h"
#include "scene/material_library.h"

namespace dpc::demo {
namespace {

/// The eight band values with two decimals, as the library tables give them.
std::string bandText(const Bands& b) {
  std::string out;
  for (int i = 0; i < kNumBands; ++i) {
    char cell[16];
    std::snprintf(cell, sizeof cell, "%s%5.2f", i ? " " : "", double(b[i]));
    out += cell;
  }
  return out;
}

}  // namespace

int listMaterials() {
  const auto& library = materialLibrary();
  std::printf(
      "%zu materials in %s (absorption and scattering per octave band: "
      "63 125 250 500 1k 2k 4k 8k Hz)\n",
      library.size(), kMaterialLibraryFile);
  for (const LibraryMaterial& e : library) {
    std::printf("\n%s: %s\n", e.material.name.c_str(), e.description.c_str());
    std::printf("  absorption  %s\n", bandText(e.material.absorption).c_str());
    std::printf("  scattering  %s\n", bandText(e.material.scattering).c_str());
    std::printf("  source      %s\n", e.source.c_str());
  }
  return 0;
}

}  // namespace dpc::demo
