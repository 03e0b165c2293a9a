// dpc-demo --list-materials: the materials library (scene/material_library.h) as a table.
#pragma once

namespace dpc::demo {

/// Prints one block per library entry to stdout: name, description, absorption per octave
/// band (63 Hz .. 8 kHz), scattering and the cited source. Returns the exit status (0).
/// Main thread; allocates.
int listMaterials();

}  // namespace dpc::demo
