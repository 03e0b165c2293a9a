#include "bake/bake_layout.h"

#include <cmath>
#include <stdexcept>

#include "bake/hdf5_util.h"
#include "common/input_error.h"
#include "common/input_file.h"

namespace dpc::bake {

const std::vector<ProbeDataset> kProbeDatasets = {
    {"energy", &ProbeResult::energy,
     [](const ProbeShape& s) { return std::vector<hsize_t>{s.sources, s.bins, kNumBands}; }},
    {"sh_energy", &ProbeResult::sh,
     [](const ProbeShape& s) {
       return std::vector<hsize_t>{s.sources, s.directionalBins(), kShChannels, kNumBands};
     }},
    {"direct/delay_s", &ProbeResult::directDelay,
     [](const ProbeShape& s) { return std::vector<hsize_t>{s.sources}; }},
    {"direct/energy", &ProbeResult::directEnergy,
     [](const ProbeShape& s) { return std::vector<hsize_t>{s.sources, kNumBands}; }},
    {"direct/direction", &ProbeResult::directDirection,
     [](const ProbeShape& s) { return std::vector<hsize_t>{s.sources, 3}; }},
    {"parameters", &ProbeResult::parameters,
     [](const ProbeShape& s) {
       return std::vector<hsize_t>{s.sources, kParameterRows, kParameters};
     }},
    {"parameters_ci95", &ProbeResult::parametersCi,
     [](const ProbeShape& s) {
       return std::vector<hsize_t>{s.sources, kParameterRows, kParameters};
     }},
    {"sti", &ProbeResult::sti, [](const ProbeShape& s) { return std::vector<hsize_t>{s.sources}; }},
    {"sti_ci95", &ProbeResult::stiCi,
     [](const ProbeShape& s) { return std::vector<hsize_t>{s.sources}; }},
    {"early/count", &ProbeResult::earlyCount,
     [](const ProbeShape& s) { return std::vector<hsize_t>{s.sources}; }},
    {"early/found", &ProbeResult::earlyFound,
     [](const ProbeShape& s) { return std::vector<hsize_t>{s.sources}; }},
    {"early/paths", &ProbeResult::early,
     [](const ProbeShape& s) {
       return std::vector<hsize_t>{s.sources, kEarlyPaths, kEarlyPathFloats};
     }},
    {"early/energy", &ProbeResult::earlyEnergy,
     [](const ProbeShape& s) { return std::vector<hsize_t>{s.sources, s.bins, kNumBands}; }},
    {"early/sh_energy", &ProbeResult::earlySh,
     [](const ProbeShape& s) {
       return std::vector<hsize_t>{s.sources, s.directionalBins(), kShChannels, kNumBands};
     }},
};

size_t rowFloats(const ProbeDataset& d, const ProbeShape& shape) {
  size_t n = 1;
  for (const hsize_t x : d.shape(shape)) n *= size_t(x);
  return n;
}

std::vector<hsize_t> withProbes(size_t probes, std::vector<hsize_t> rest) {
  rest.insert(rest.begin(), hsize_t(probes));
  return rest;
}

namespace {

void writeHashes(hid_t root, const SettingsHash& hashes, int64_t version) {
  h5::writeAttribute(root, "settings_hash", combinedHash(hashes, version));
  const int groups = version < 6 ? kSettingGroupsVersion5 : kSettingGroups;
  for (int g = 0; g < groups; ++g)
    h5::writeAttribute(root, kSettingGroupInfo[size_t(g)].attribute, hashes[size_t(g)]);
}

std::string joined(const std::vector<std::string>& names) {
  std::string s;
  for (const std::string& n : names) s += (s.empty() ? "" : ",") + n;
  return s;
}

}  // namespace

void writeHeaderAttributes(hid_t root, const BakeHeader& h) {
  using h5::writeAttribute;
  writeAttribute(root, "format", std::string(kBakeFormat));
  writeAttribute(root, "version", h.version);
  writeAttribute(root, "complete", int64_t(0));
  writeAttribute(root, "scene", h.scenePath);
  writeHashes(root, h.hashes, h.version);
  writeAttribute(root, "seed", h.seed);
  writeAttribute(root, "spacing_m", h.grid.spacingM);
  writeAttribute(root, "height_m", h.grid.heightM);
  writeAttribute(root, "probe_layout", probeLayout(h.grid, h.grid.spacingM == 0.0));
  writeAttribute(root, "probe_radius_m", double(h.grid.radiusM));
  writeAttribute(root, "rays_per_frame", int64_t(h.settings.rays));
  writeAttribute(root, "frames", int64_t(h.settings.frames));
  writeAttribute(root, "sub_streams", int64_t(h.settings.subStreams));
  writeAttribute(root, "ir_length_s", h.settings.irLength);
  writeAttribute(root, "bin_seconds", 1e-3);
  writeAttribute(root, "directional_bin_seconds", 1e-3 * double(kDirectionalBinFactor));
  writeAttribute(root, "sh_order", int64_t(kShOrder));
  writeAttribute(root, "sh_convention", std::string(kShConvention));
  writeAttribute(root, "grid_candidates", uint64_t(h.probes.candidates));
  writeAttribute(root, "skipped_outside", uint64_t(h.probes.outside));
  writeAttribute(root, "skipped_inside_geometry", uint64_t(h.probes.insideGeometry));
  writeAttribute(root, "skipped_near_surface", uint64_t(h.probes.nearSurface));
  writeAttribute(root, "parameter_columns",
                 joined(std::vector<std::string>(kParameterNames.begin(), kParameterNames.end())));
  std::vector<std::string> columns;
  for (const ProbeDataset& d : kProbeDatasets) columns.push_back(d.name);
  writeAttribute(root, "checksum_columns", joined(columns));
}

WaveLayout waveLayout(const SceneDesc& scene, double irLength) {
  WaveLayout w;
  w.enabled = scene.wave.enabled;
  if (!w.enabled) return w;
  w.sampleRate = scene.audio.sampleRate;
  w.maxFrequencyHz = scene.wave.maxFrequencyHz;
  w.crossoverHz = scene.wave.crossover();
  w.gridSpacingM = scene.wave.spacing(scene.propagation.speedOfSound);
  w.samples = waveSamples(irLength, w.sampleRate);
  return w;
}

void writeWaveAttributes(hid_t file, const WaveLayout& w) {
  const h5::Id set = h5::check(H5Dopen2(file, kWaveBand, H5P_DEFAULT), kWaveBand);
  h5::writeAttribute(set.get(), "sample_rate_hz", int64_t(w.sampleRate));
  h5::writeAttribute(set.get(), "max_frequency_hz", w.maxFrequencyHz);
  h5::writeAttribute(set.get(), "crossover_hz", w.crossoverHz);
  h5::writeAttribute(set.get(), "grid_spacing_m", w.gridSpacingM);
}

WaveLayout readWaveLayout(hid_t file) {
  WaveLayout w;
  if (!h5::exists(file, kWaveBand)) return w;
  const auto dims = h5::datasetDims(file, kWaveBand);
  if (dims.size() != 3) throw std::runtime_error(std::string("/") + kWaveBand + ": not 3-D");
  const h5::Id set = h5::check(H5Dopen2(file, kWaveBand, H5P_DEFAULT), kWaveBand);
  const std::string at = std::string("/") + kWaveBand + ": ";
  w.enabled = true;
  w.samples = size_t(dims[2]);
  w.sampleRate = int(h5::readInt(set.get(), "sample_rate_hz"));
  w.maxFrequencyHz = h5::readDouble(set.get(), "max_frequency_hz");
  w.crossoverHz = h5::readDouble(set.get(), "crossover_hz");
  w.gridSpacingM = h5::readDouble(set.get(), "grid_spacing_m");
  if (!(w.sampleRate >= kMinSignalRateHz && w.sampleRate <= kMaxSignalRateHz))
    throw std::runtime_error(at + "sample_rate_hz " + std::to_string(w.sampleRate));
  if (!(w.crossoverHz > 0.0 && w.crossoverHz < w.maxFrequencyHz &&
        2.0 * w.maxFrequencyHz < w.sampleRate))
    throw std::runtime_error(at + "crossover_hz and max_frequency_hz out of order");
  return w;
}

namespace {

/// An attribute read, a failed read refused as InputError naming it.
template <typename Read>
auto attribute(const std::string& path, const char* name, Read read) {
  try {
    return read(name);
  } catch (const std::runtime_error& e) {
    throw InputError(path, name, e.what());
  }
}

}  // namespace

void checkFormat(hid_t root, const std::string& path) {
  const auto text = [root](const char* n) { return h5::readString(root, n); };
  const auto number = [root](const char* n) { return h5::readInt(root, n); };
  if (attribute(path, "format", text) != kBakeFormat)
    throw InputError(path, "format", "not a " + std::string(kBakeFormat) + " file");
  const int64_t version = attribute(path, "version", number);
  if (version < kOldestBakeFormatVersion || version > kBakeFormatVersion)
    throw InputError(path, "version",
                     "format version " + std::to_string(version) + ", this dpc reads versions " +
                         std::to_string(kOldestBakeFormatVersion) + " and " +
                         std::to_string(kBakeFormatVersion) + " only" +
                         (version < kOldestBakeFormatVersion
                              ? " (the exact early paths' energy, early/energy, since 5): bake "
                                "again"
                              : ""));
  if (attribute(path, "sh_order", number) != kShOrder)
    throw InputError(path, "sh_order", "this dpc reads order " + std::to_string(kShOrder));
  if (attribute(path, "sh_convention", text) != kShConvention)
    throw InputError(path, "sh_convention", "this dpc reads " + std::string(kShConvention));
}

BakeHeader readHeaderAttributes(hid_t root) {
  BakeHeader h;
  h.version = h5::readInt(root, "version");
  h.scenePath = h5::readString(root, "scene");
  // Version 5 has no wave group: its bakes are those of scenes without the wave band.
  SceneDesc noWave;
  h.hashes[size_t(SettingGroup::kWave)] = waveHash(noWave);
  const int groups = h.version < 6 ? kSettingGroupsVersion5 : kSettingGroups;
  for (int g = 0; g < groups; ++g)
    h.hashes[size_t(g)] = h5::readUint(root, kSettingGroupInfo[size_t(g)].attribute);
  if (h5::readUint(root, "settings_hash") != combinedHash(h.hashes, h.version))
    throw std::runtime_error("settings_hash: does not match the hash_* attributes");
  h.seed = h5::readUint(root, "seed");
  h.grid.spacingM = h5::readDouble(root, "spacing_m");
  h.grid.heightM = h5::readDouble(root, "height_m");
  h.grid.radiusM = float(h5::readDouble(root, "probe_radius_m"));
  h.settings.rays = int(h5::readInt(root, "rays_per_frame"));
  h.settings.frames = int(h5::readInt(root, "frames"));
  h.settings.subStreams = int(h5::readInt(root, "sub_streams"));
  h.settings.irLength = h5::readDouble(root, "ir_length_s");
  h.probes.candidates = h5::readUint(root, "grid_candidates");
  h.probes.outside = h5::readUint(root, "skipped_outside");
  h.probes.insideGeometry = h5::readUint(root, "skipped_inside_geometry");
  h.probes.nearSurface = h5::readUint(root, "skipped_near_surface");
  return h;
}

namespace {

std::string shapeText(const std::vector<hsize_t>& dims) {
  std::string s = "[";
  for (size_t i = 0; i < dims.size(); ++i) s += (i ? ", " : "") + std::to_string(dims[i]);
  return s + "]";
}

}  // namespace

void validateShapes(hid_t file, const BakeHeader& h) {
  const size_t probes = h.probes.positions.size();
  auto expect = [&](const std::string& name, const std::vector<hsize_t>& want) {
    std::vector<hsize_t> got;
    try {
      got = h5::datasetDims(file, name);
    } catch (const std::runtime_error& e) {
      throw std::runtime_error("/" + name + ": " + e.what());
    }
    if (got != want)
      throw std::runtime_error("/" + name + ": shape " + shapeText(got) + ", expected " +
                               shapeText(want));
  };
  expect("probes/done", {probes});
  expect("checksums", {probes, kProbeDatasets.size()});
  expect("band_centres_hz", {kNumBands});
  for (const ProbeDataset& d : kProbeDatasets) expect(d.name, withProbes(probes, d.shape(h.shape)));
  if (!h.wave.enabled) return;
  const size_t sources = h.sources.size();
  expect(kWaveBand, {sources, probes, h.wave.samples});
  expect(kWaveReached, {sources, probes});
  expect(kWaveDone, {sources});
  expect(kWaveChecksums, {sources});
  if (h.wave.samples != waveSamples(h.settings.irLength, h.wave.sampleRate))
    throw std::runtime_error(std::string("/") + kWaveBand + ": " + std::to_string(h.wave.samples) +
                             " samples, ir_length_s at " + "sample_rate_hz gives " +
                             std::to_string(waveSamples(h.settings.irLength, h.wave.sampleRate)));
}

}  // namespace dpc::bake
