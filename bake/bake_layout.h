// The bake file's layout (docs/bake-format.md), shared by its writer, its reader and its
// verification (bake/bake_file.h): the per-probe datasets and their shapes, the root
// attributes of a header, and the checks of format, version and shapes.
// Control thread; allocates; errors as std::runtime_error naming the attribute or dataset
// (bake/bake_file.cpp adds the file) or InputError naming the file and attribute.
#pragma once

#include <hdf5.h>

#include <cstdint>
#include <string>
#include <vector>

#include "bake/probe_bake.h"
#include "bake/probe_grid.h"
#include "bake/settings_hash.h"

namespace dpc::bake {

/// Format name and version written to and required from the root attributes.
inline constexpr const char* kBakeFormat = "dpc-bake";
inline constexpr int kBakeFormatVersion = 5;
/// The `sh_convention` attribute: channel order and normalisation of `sh_energy`.
inline constexpr const char* kShConvention = "ACN/SN3D";

/// Everything a bake is fixed by: the scene, the grid and the settings.
struct BakeHeader {
  std::string scenePath;  ///< the scene file, absolute
  SettingsHash hashes{};  ///< settingsHash(scene, settings, probe positions)
  uint64_t seed = 1;      ///< the scene's propagation seed
  GridRequest grid;
  BakeSettings settings;
  ProbeGrid probes;                  ///< kept probes and the skipped counts
  std::vector<glm::vec3> sources;    ///< static source positions, metres
  ProbeShape shape;
};

/// One per-probe float dataset: its name, the ProbeResult member it stores, and its shape after
/// the probe dimension.
struct ProbeDataset {
  const char* name;
  std::vector<float> ProbeResult::*member;
  std::vector<hsize_t> (*shape)(const ProbeShape&);
};
/// Every per-probe dataset, in the order of the columns of /checksums.
extern const std::vector<ProbeDataset> kProbeDatasets;
/// Floats of one probe's row of dataset d.
size_t rowFloats(const ProbeDataset& d, const ProbeShape& shape);
std::vector<hsize_t> withProbes(size_t probes, std::vector<hsize_t> rest);

/// Writes every root attribute of the header (`complete` 0).
void writeHeaderAttributes(hid_t root, const BakeHeader& h);
/// Refuses a file of another format or version, or with other spherical harmonics than this
/// build writes: InputError(path, attribute, ...).
void checkFormat(hid_t root, const std::string& path);
/// The header attributes of an open file (std::runtime_error naming the attribute).
BakeHeader readHeaderAttributes(hid_t root);
/// Checks that every dataset has the shape the header implies (std::runtime_error naming it).
void validateShapes(hid_t file, const BakeHeader& h);

}  // namespace dpc::bake
