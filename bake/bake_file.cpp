#include "bake/bake_file.h"

#include <chrono>
#include <cstring>
#include <filesystem>
#include <limits>
#include <stdexcept>

#include "bake/hdf5_util.h"
#include "common/input_error.h"
#include "common/input_file.h"
#include "scene/trajectory.h"

namespace dpc::bake {
namespace {

/// One per-probe float dataset: its name, the ProbeResult member it stores, and its shape after
/// the probe dimension.
struct ProbeDataset {
  const char* name;
  std::vector<float> ProbeResult::*member;
  std::vector<hsize_t> (*shape)(const ProbeShape&);
};

const ProbeDataset kProbeDatasets[] = {
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
};

std::vector<hsize_t> withProbes(size_t probes, std::vector<hsize_t> rest) {
  rest.insert(rest.begin(), hsize_t(probes));
  return rest;
}

/// FNV-1a, 64 bit, over raw bytes.
void fnv(uint64_t& h, const void* data, size_t n) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 0x100000001b3ULL;
}

void writeHeaderAttributes(hid_t root, const BakeHeader& h) {
  using h5::writeAttribute;
  writeAttribute(root, "format", std::string(kBakeFormat));
  writeAttribute(root, "version", int64_t(kBakeFormatVersion));
  writeAttribute(root, "complete", int64_t(0));
  writeAttribute(root, "scene", h.scenePath);
  writeAttribute(root, "mesh_hash", h.meshHash);
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
  std::string columns;
  for (const char* n : kParameterNames) columns += columns.empty() ? n : std::string(",") + n;
  writeAttribute(root, "parameter_columns", columns);
}

/// An attribute read, a failed read refused as InputError naming it.
template <typename Read>
auto attribute(const std::string& path, const char* name, Read read) {
  try {
    return read(name);
  } catch (const std::runtime_error& e) {
    throw InputError(path, name, e.what());
  }
}

/// Refuses a file of another format or version, or with other spherical harmonics than this
/// build writes: InputError naming the attribute.
void checkFormat(hid_t root, const std::string& path) {
  const auto text = [root](const char* n) { return h5::readString(root, n); };
  const auto number = [root](const char* n) { return h5::readInt(root, n); };
  if (attribute(path, "format", text) != kBakeFormat)
    throw InputError(path, "format", "not a " + std::string(kBakeFormat) + " file");
  const int64_t version = attribute(path, "version", number);
  if (version != kBakeFormatVersion)
    throw InputError(path, "version",
                     "format version " + std::to_string(version) + ", this dpc reads version " +
                         std::to_string(kBakeFormatVersion) + " only" +
                         (version < kBakeFormatVersion
                              ? " (direction as spherical-harmonic energy since 3): bake again"
                              : ""));
  if (attribute(path, "sh_order", number) != kShOrder)
    throw InputError(path, "sh_order", "this dpc reads order " + std::to_string(kShOrder));
  if (attribute(path, "sh_convention", text) != kShConvention)
    throw InputError(path, "sh_convention", "this dpc reads " + std::string(kShConvention));
}

/// Reads the header attributes of an open file (std::runtime_error naming the attribute;
/// open() adds the file name).
BakeHeader readHeaderAttributes(hid_t root) {
  BakeHeader h;
  h.scenePath = h5::readString(root, "scene");
  h.meshHash = h5::readUint(root, "mesh_hash");
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

std::vector<glm::vec3> readPoints(hid_t file, const std::string& name) {
  const auto dims = h5::datasetDims(file, name);
  if (dims.size() != 2 || dims[1] != 3) throw std::runtime_error("shape is not [n, 3]");
  std::vector<glm::vec3> points(dims[0]);
  h5::readAll(file, name, H5T_NATIVE_FLOAT, points.data());
  return points;
}

std::string shapeText(const std::vector<hsize_t>& dims) {
  std::string s = "[";
  for (size_t i = 0; i < dims.size(); ++i) s += (i ? ", " : "") + std::to_string(dims[i]);
  return s + "]";
}

/// Checks that every dataset has the shape the header implies; throws naming the dataset.
void validateShapes(hid_t file, const BakeHeader& h) {
  const size_t probes = h.probes.positions.size();
  auto expect = [&](const std::string& name, const std::vector<hsize_t>& want) {
    std::vector<hsize_t> got;
    try {
      got = h5::datasetDims(file, name);
    } catch (const std::runtime_error&) {
      throw std::runtime_error("/" + name + ": missing");
    }
    if (got != want)
      throw std::runtime_error("/" + name + ": shape " + shapeText(got) + ", expected " +
                               shapeText(want));
  };
  expect("probes/done", {probes});
  expect("band_centres_hz", {kNumBands});
  for (const ProbeDataset& d : kProbeDatasets) expect(d.name, withProbes(probes, d.shape(h.shape)));
}

}  // namespace

uint64_t sceneHash(const SceneDesc& scene) {
  uint64_t h = 0xcbf29ce484222325ULL;
  const Mesh& m = scene.mesh;
  fnv(h, m.vertices.data(), m.vertices.size() * sizeof(glm::vec3));
  fnv(h, m.triangles.data(), m.triangles.size() * sizeof(m.triangles[0]));
  fnv(h, m.materialIndex.data(), m.materialIndex.size() * sizeof(uint32_t));
  for (const Material& mat : scene.materials) {
    fnv(h, &mat.absorption, sizeof mat.absorption);
    fnv(h, &mat.scattering, sizeof mat.scattering);
  }
  for (const SourceDesc& s : scene.sources) {
    const glm::vec3 p = sourcePositionAt(s, 0.0);
    fnv(h, &p, sizeof p);
  }
  const PropagationSettings& p = scene.propagation;
  for (const float v : {float(p.maxOrder), p.speedOfSound, p.temperatureC, p.humidityPercent,
                        float(p.airAbsorption), float(p.diffraction), p.rouletteThreshold})
    fnv(h, &v, sizeof v);
  return h;
}

struct BakeFile::Impl {
  std::string path;
  h5::Id file;
  BakeHeader header;
  double commitSeconds = 0.0;
};

BakeFile::BakeFile(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
BakeFile::BakeFile(BakeFile&&) noexcept = default;
BakeFile& BakeFile::operator=(BakeFile&&) noexcept = default;
BakeFile::~BakeFile() = default;

const BakeHeader& BakeFile::header() const { return impl_->header; }
const std::string& BakeFile::path() const { return impl_->path; }

BakeFile BakeFile::create(const std::string& path, const std::string& displayPath,
                          const BakeHeader& header) {
  h5::silenceHdf5();
  auto impl = std::make_unique<Impl>();
  impl->path = displayPath;
  impl->header = header;
  impl->file = h5::check(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT),
                         displayPath + ": cannot create the file");
  const hid_t f = impl->file.get();
  const h5::Id root = h5::check(H5Gopen2(f, "/", H5P_DEFAULT), displayPath + ": no root group");
  writeHeaderAttributes(root.get(), header);
  const size_t probes = header.probes.positions.size();
  h5::createDataset(f, "probes/position", H5T_NATIVE_FLOAT, {probes, 3}, false);
  h5::writeAll(f, "probes/position", H5T_NATIVE_FLOAT, header.probes.positions.data());
  h5::createDataset(f, "probes/done", H5T_NATIVE_UINT8, {probes}, false);
  const std::vector<uint8_t> none(probes, 0);
  h5::writeAll(f, "probes/done", H5T_NATIVE_UINT8, none.data());
  h5::createDataset(f, "sources/position", H5T_NATIVE_FLOAT, {header.sources.size(), 3}, false);
  h5::writeAll(f, "sources/position", H5T_NATIVE_FLOAT, header.sources.data());
  h5::createDataset(f, "band_centres_hz", H5T_NATIVE_FLOAT, {kNumBands}, false);
  h5::writeAll(f, "band_centres_hz", H5T_NATIVE_FLOAT, kBandCentreHz.data());
  for (const ProbeDataset& d : kProbeDatasets)
    h5::createDataset(f, d.name, H5T_NATIVE_FLOAT, withProbes(probes, d.shape(header.shape)),
                      true);
  H5Fflush(f, H5F_SCOPE_GLOBAL);
  return BakeFile(std::move(impl));
}

BakeFile BakeFile::open(const std::string& path, bool writable) {
  h5::silenceHdf5();
  // A folder, a FIFO or a device is named as such (not "no such file"), before HDF5 reads it.
  checkInputFile(path, std::numeric_limits<std::uintmax_t>::max(), path, "", "bake");
  if (H5Fis_hdf5(path.c_str()) <= 0)
    throw InputError(path, "", "not an HDF5 file, or truncated");
  auto impl = std::make_unique<Impl>();
  impl->path = path;
  impl->file = h5::Id(H5Fopen(path.c_str(), writable ? H5F_ACC_RDWR : H5F_ACC_RDONLY, H5P_DEFAULT));
  if (!impl->file.valid()) throw InputError(path, "", "cannot open (truncated or corrupt HDF5)");
  try {
    const hid_t f = impl->file.get();
    const h5::Id root = h5::check(H5Gopen2(f, "/", H5P_DEFAULT), "no root group");
    checkFormat(root.get(), path);
    impl->header = readHeaderAttributes(root.get());
    impl->header.probes.positions = readPoints(f, "probes/position");
    impl->header.sources = readPoints(f, "sources/position");
    impl->header.shape = {impl->header.sources.size(),
                          responseBins(impl->header.settings.irLength)};
    validateShapes(f, impl->header);
  } catch (const InputError&) {
    throw;
  } catch (const std::runtime_error& e) {
    throw InputError(path, "", e.what());
  }
  return BakeFile(std::move(impl));
}

std::vector<uint8_t> BakeFile::done() const {
  std::vector<uint8_t> d(impl_->header.probes.positions.size());
  try {
    h5::readAll(impl_->file.get(), "probes/done", H5T_NATIVE_UINT8, d.data());
  } catch (const std::runtime_error& e) {
    throw InputError(impl_->path, "/probes/done", e.what());
  }
  return d;
}

bool BakeFile::complete() const {
  const h5::Id root = h5::check(H5Gopen2(impl_->file.get(), "/", H5P_DEFAULT), "root");
  return h5::readInt(root.get(), "complete") == 1;
}

double BakeFile::commitSeconds() const { return impl_->commitSeconds; }

void BakeFile::commit(size_t probe, const ProbeResult& result) {
  const auto start = std::chrono::steady_clock::now();
  const hid_t f = impl_->file.get();
  for (const ProbeDataset& d : kProbeDatasets)
    h5::writeRow(f, d.name, H5T_NATIVE_FLOAT, probe, (result.*d.member).data());
  const uint8_t one = 1;
  h5::writeRow(f, "probes/done", H5T_NATIVE_UINT8, probe, &one);
  if (H5Fflush(f, H5F_SCOPE_GLOBAL) < 0) throw std::runtime_error(impl_->path + ": flush failed");
  impl_->commitSeconds +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void BakeFile::markComplete() {
  const h5::Id root = h5::check(H5Gopen2(impl_->file.get(), "/", H5P_DEFAULT), "root");
  h5::writeAttribute(root.get(), "complete", int64_t(1));
  if (H5Fflush(impl_->file.get(), H5F_SCOPE_GLOBAL) < 0)
    throw std::runtime_error(impl_->path + ": flush failed");
}

std::vector<float> BakeFile::readAll(const std::string& dataset) const {
  size_t n = 1;
  try {
    for (const hsize_t d : h5::datasetDims(impl_->file.get(), dataset)) n *= d;
    std::vector<float> out(n);
    h5::readAll(impl_->file.get(), dataset, H5T_NATIVE_FLOAT, out.data());
    return out;
  } catch (const std::runtime_error& e) {
    throw InputError(impl_->path, "/" + dataset, e.what());
  }
}

}  // namespace dpc::bake
