// The bake file's layout (docs/bake-format.md), shared by its writer, its reader and its
// verification (bake/bake_file.h): the per-probe datasets and their shapes, the root
// attributes of a header, and the checks of format, version and shapes.
// Control thread; allocates; errors as std::runtime_error naming the attribute or dataset
// (bake/bake_file.cpp adds the file) or InputError naming the file and attribute.
#pragma once

#include <hdf5.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "bake/probe_bake.h"
#include "bake/probe_grid.h"
#include "bake/settings_hash.h"

namespace dpc::bake {

/// Format name and version written to and required from the root attributes.
inline constexpr const char* kBakeFormat = "dpc-bake";
inline constexpr int kBakeFormatVersion = 6;
/// The oldest version read: 5 is 6 without the wave band (and without `hash_wave`).
inline constexpr int kOldestBakeFormatVersion = 5;
/// The `sh_convention` attribute: channel order and normalisation of `sh_energy`.
inline constexpr const char* kShConvention = "ACN/SN3D";

/// The wave band of a bake (docs/bake-format.md, "The wave band"): per source and probe the
/// pressure IR of the scene's wave simulation (wave/wave_band.h) before any crossover, stored
/// when the scene's wave.enabled is set. `samples` at `sampleRate` Hz: the response's length.
struct WaveLayout {
  bool enabled = false;
  int sampleRate = 48000;        ///< Hz (the scene's audio.sample_rate)
  double maxFrequencyHz = 0.0;   ///< the simulation's maximum frequency (wave.max_frequency)
  double crossoverHz = 0.0;      ///< the crossover to join it at (wave.crossover_hz in use)
  double gridSpacingM = 0.0;     ///< the grid's target spacing, metres
  size_t samples = 0;            ///< per IR
};
/// Samples of a wave IR irLength seconds long at `rate` Hz (wave/wave_band.h's count).
inline size_t waveSamples(double irLength, int rate) {
  return size_t(std::llround(irLength * double(rate)));
}
/// The wave layout a bake of `scene` with responses irLength seconds long stores.
WaveLayout waveLayout(const SceneDesc& scene, double irLength);

/// Everything a bake is fixed by: the scene, the grid and the settings.
struct BakeHeader {
  int64_t version = kBakeFormatVersion;  ///< the file's format version (5 or 6)
  std::string scenePath;  ///< the scene file, absolute
  SettingsHash hashes{};  ///< settingsHash(scene, settings, probe positions)
  uint64_t seed = 1;      ///< the scene's propagation seed
  GridRequest grid;
  BakeSettings settings;
  ProbeGrid probes;                  ///< kept probes and the skipped counts
  std::vector<glm::vec3> sources;    ///< static source positions, metres
  ProbeShape shape;
  WaveLayout wave;
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

/// The wave band's datasets (present when WaveLayout::enabled): [S, P, samples] float32, its
/// attributes on it; [S, P] uint8, 1 where the probe lies in air the source's grid reaches;
/// [S] uint8, 1 where the source's row is stored; [S] uint32, the CRC-32 of a source's row of
/// kWaveBand then of kWaveReached.
inline constexpr const char* kWaveBand = "wave/band";
inline constexpr const char* kWaveReached = "wave/reached";
inline constexpr const char* kWaveDone = "wave/done";
inline constexpr const char* kWaveChecksums = "wave/checksums";

/// Writes every root attribute of the header (`complete` 0).
void writeHeaderAttributes(hid_t root, const BakeHeader& h);
/// Writes the wave band's attributes on dataset kWaveBand of `file` (enabled layouts only).
void writeWaveAttributes(hid_t file, const WaveLayout& w);
/// Refuses a file of another format or version, or with other spherical harmonics than this
/// build writes: InputError(path, attribute, ...).
void checkFormat(hid_t root, const std::string& path);
/// The header attributes of an open file (std::runtime_error naming the attribute), and the
/// wave layout's when the file holds kWaveBand (samples from its shape).
BakeHeader readHeaderAttributes(hid_t root);
WaveLayout readWaveLayout(hid_t file);
/// Checks that every dataset has the shape the header implies (std::runtime_error naming it).
void validateShapes(hid_t file, const BakeHeader& h);

}  // namespace dpc::bake
