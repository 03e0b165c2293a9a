#include "bake/bake_file.h"

#include <chrono>
#include <cstdio>
#include <cstring>
#include <limits>
#include <stdexcept>

#include "bake/bake_lock.h"
#include "bake/bake_verify.h"
#include "bake/hdf5_util.h"
#include "common/input_error.h"
#include "common/input_file.h"
#include "scene/limits.h"
#include "scene/trajectory.h"

namespace dpc::bake {
namespace {

/// The groups the datasets live in, created before them (no timestamps).
constexpr const char* kGroups[] = {"probes", "sources", "direct", "early"};

/// A failed write as the InputError of the file and dataset, with the system's reason.
[[noreturn]] void writeFailed(const std::string& path, const std::string& dataset,
                              const std::runtime_error& e) {
  throw InputError(path, dataset, std::string("cannot write: ") + e.what());
}

void createLayout(hid_t f, const BakeHeader& header) {
  const size_t probes = header.probes.positions.size();
  for (const char* g : kGroups) h5::createGroup(f, g);
  h5::createDataset(f, "probes/position", H5T_NATIVE_FLOAT, {probes, 3});
  h5::createDataset(f, "probes/done", H5T_NATIVE_UINT8, {probes});
  h5::createDataset(f, "sources/position", H5T_NATIVE_FLOAT, {header.sources.size(), 3});
  h5::createDataset(f, "band_centres_hz", H5T_NATIVE_FLOAT, {kNumBands});
  h5::createDataset(f, "checksums", H5T_STD_U32LE, {probes, kProbeDatasets.size()});
  for (const ProbeDataset& d : kProbeDatasets)
    h5::createDataset(f, d.name, H5T_IEEE_F32LE, withProbes(probes, d.shape(header.shape)));
  if (!header.wave.enabled) return;
  const size_t sources = header.sources.size();
  h5::createGroup(f, "wave");
  h5::createDataset(f, kWaveBand, H5T_IEEE_F32LE, {sources, probes, header.wave.samples});
  h5::createDataset(f, kWaveReached, H5T_NATIVE_UINT8, {sources, probes});
  h5::createDataset(f, kWaveDone, H5T_NATIVE_UINT8, {sources});
  h5::createDataset(f, kWaveChecksums, H5T_STD_U32LE, {sources});
  writeWaveAttributes(f, header.wave);
}

/// The datasets fixed at creation (after reserveFile: raw writes into reserved bytes).
void writeFixed(hid_t f, const BakeHeader& header) {
  if (!header.probes.positions.empty())
    h5::writeAll(f, "probes/position", H5T_NATIVE_FLOAT, header.probes.positions.data());
  if (!header.sources.empty())
    h5::writeAll(f, "sources/position", H5T_NATIVE_FLOAT, header.sources.data());
  h5::writeAll(f, "band_centres_hz", H5T_NATIVE_FLOAT, kBandCentreHz.data());
}

/// The header and fixed datasets of an open file, checked (std::runtime_error naming what is
/// wrong; InputError for the format).
BakeHeader readHeader(hid_t f, const std::string& path) {
  const h5::Id root = h5::check(H5Gopen2(f, "/", H5P_DEFAULT), "no root group");
  checkFormat(root.get(), path);
  BakeHeader h = readHeaderAttributes(root.get());
  h.wave = readWaveLayout(f);
  // hash_wave says whether the scene baked had the wave band: the datasets must agree.
  const bool waveHashed = h.hashes[size_t(SettingGroup::kWave)] != waveHash(SceneDesc{});
  if (waveHashed != h.wave.enabled)
    throw std::runtime_error(std::string("/") + kWaveBand + ": " +
                             (waveHashed ? "missing, yet hash_wave says the bake carries the "
                                           "wave band"
                                         : "present, yet hash_wave says the bake has no wave "
                                           "band"));
  auto points = [f](const char* name) {
    try {
      const auto dims = h5::datasetDims(f, name);
      if (dims.size() != 2 || dims[1] != 3 || dims[0] > (hsize_t(1) << 32))
        throw std::runtime_error("shape is not [n, 3]");
      std::vector<glm::vec3> p(dims[0]);
      if (!p.empty()) h5::readAll(f, name, H5T_NATIVE_FLOAT, p.data());
      return p;
    } catch (const std::runtime_error& e) {
      throw std::runtime_error(std::string("/") + name + ": " + e.what());
    }
  };
  h.probes.positions = points("probes/position");
  h.sources = points("sources/position");
  if (!(h.settings.irLength > 0.0 && h.settings.irLength <= 3600.0))
    throw std::runtime_error("ir_length_s: " + valueText(h.settings.irLength) +
                             " s is outside (0, 3600]");
  h.shape = {h.sources.size(), responseBins(h.settings.irLength)};
  validateShapes(f, h);
  std::vector<float> bands(kNumBands);
  h5::readAll(f, "band_centres_hz", H5T_NATIVE_FLOAT, bands.data());
  if (uint32_t(h5::readUint(root.get(), "fixed_crc32")) != fixedChecksum(h, bands))
    throw std::runtime_error("fixed_crc32: the probe or source positions or band centres are "
                             "damaged");
  return h;
}

bool readComplete(hid_t f, const std::string& path) {
  try {
    const h5::Id root = h5::check(H5Gopen2(f, "/", H5P_DEFAULT), "no root group");
    const int64_t c = h5::readInt(root.get(), "complete");
    if (c != 0 && c != 1) throw std::runtime_error(std::to_string(c) + " (0 or 1 expected)");
    return c == 1;
  } catch (const std::runtime_error& e) {
    throw InputError(path, "complete", e.what());
  }
}

/// The 8-byte signature every HDF5 file starts with, and the superblock version dpc writes
/// (format 2, checksummed; fileAccess()).
constexpr unsigned char kHdf5Signature[8] = {0x89, 'H', 'D', 'F', '\r', '\n', 0x1a, '\n'};
constexpr unsigned char kSuperblockVersion = 2;

/// Refuses, before HDF5 parses anything, a file that does not start with an HDF5 superblock of
/// the version dpc writes: a superblock of version 0 or 1 carries no checksum, so HDF5 would
/// follow whatever addresses a damaged one holds.
void checkHdf5Signature(const std::string& path) {
  unsigned char head[9] = {};
  std::FILE* f = std::fopen(path.c_str(), "rb");
  const size_t n = f ? std::fread(head, 1, sizeof head, f) : 0;
  if (f) std::fclose(f);
  if (n < sizeof head || std::memcmp(head, kHdf5Signature, sizeof kHdf5Signature) != 0)
    throw InputError(path, "", "not an HDF5 file, or truncated");
  if (head[8] != kSuperblockVersion)
    throw InputError(path, "", "HDF5 superblock version " + std::to_string(head[8]) +
                                   ", dpc writes and reads version " +
                                   std::to_string(kSuperblockVersion) + " (checksummed) only");
}

}  // namespace

struct BakeFile::Impl {
  std::string path;   ///< as messages name it
  std::string file;   ///< where it is on disk (a temporary until renamed)
  h5::Id handle;
  bool writable = false;
  BakeHeader header;
  std::vector<uint8_t> stored;
  std::vector<size_t> damaged;
  std::string damageReport;
  std::vector<uint8_t> waveStored;  ///< per source, header.wave.enabled
  std::string waveDamage;
  double commitSeconds = 0.0;

  /// Opens `file` afresh and reads its header; with `verify`, checks every probe the mask
  /// says stored (bake/bake_verify.h) into stored/damaged, else takes the mask as it is.
  void load(bool write, bool verify = true);
  void writeComplete(int64_t value);
};

void BakeFile::Impl::load(bool write, bool verify) {
  writable = write;
  std::string why;
  handle = h5::openFile(file, write, why);
  if (!handle.valid()) {
    if (const long writer = BakeLock::holder(file); writer > 0)
      throw InputError(path, "", "being written by another process (pid " +
                                     std::to_string(writer) + "): wait until it is done");
    throw InputError(path, "", "cannot open (truncated or corrupt HDF5" +
                                   (why.empty() ? std::string(")") : "): " + why));
  }
  try {
    header = readHeader(handle.get(), path);
    std::vector<uint8_t> done(header.probes.positions.size());
    if (!done.empty()) h5::readAll(handle.get(), "probes/done", H5T_NATIVE_UINT8, done.data());
    if (!verify) {
      stored = std::move(done);
      waveStored.assign(header.wave.enabled ? header.sources.size() : 0, 0);
      if (!waveStored.empty())
        h5::readAll(handle.get(), kWaveDone, H5T_NATIVE_UINT8, waveStored.data());
      return;
    }
    WaveVerification w = verifyWave(handle.get(), header);
    waveStored = std::move(w.stored);
    waveDamage = std::move(w.firstProblem);
    Verification v = verifyProbes(handle.get(), header, done);
    stored = std::move(v.stored);
    damaged = std::move(v.damaged);
    damageReport = std::move(v.firstProblem);
  } catch (const InputError&) {
    throw;
  } catch (const std::runtime_error& e) {
    throw InputError(path, "", e.what());
  }
}

void BakeFile::Impl::writeComplete(int64_t value) {
  try {
    const h5::Id root = h5::check(H5Gopen2(handle.get(), "/", H5P_DEFAULT), "no root group");
    h5::writeAttribute(root.get(), "complete", value);
    h5::flushToDevice(handle.get());
  } catch (const std::runtime_error& e) {
    writeFailed(path, "complete", e);
  }
}

BakeFile::BakeFile(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
BakeFile::BakeFile(BakeFile&&) noexcept = default;
BakeFile& BakeFile::operator=(BakeFile&&) noexcept = default;
BakeFile::~BakeFile() = default;

const BakeHeader& BakeFile::header() const { return impl_->header; }
const std::string& BakeFile::path() const { return impl_->path; }
const std::vector<uint8_t>& BakeFile::done() const { return impl_->stored; }
const std::vector<size_t>& BakeFile::damaged() const { return impl_->damaged; }
const std::string& BakeFile::damageReport() const { return impl_->damageReport; }
double BakeFile::commitSeconds() const { return impl_->commitSeconds; }
const std::vector<uint8_t>& BakeFile::waveDone() const { return impl_->waveStored; }
const std::string& BakeFile::waveDamageReport() const { return impl_->waveDamage; }

BakeFile BakeFile::create(const std::string& path, const std::string& displayPath,
                          const BakeHeader& header) {
  h5::silenceHdf5();
  auto impl = std::make_unique<Impl>();
  impl->path = displayPath;
  impl->file = path;
  impl->writable = true;
  impl->header = header;
  impl->stored.assign(header.probes.positions.size(), 0);
  impl->waveStored.assign(header.wave.enabled ? header.sources.size() : 0, 0);
  try {
    const h5::Id fcpl = h5::fileCreation(), fapl = h5::fileAccess();
    impl->handle = h5::check(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, fcpl.get(), fapl.get()),
                             "cannot create the file");
    const hid_t f = impl->handle.get();
    createLayout(f, header);
    const h5::Id root = h5::check(H5Gopen2(f, "/", H5P_DEFAULT), "no root group");
    writeHeaderAttributes(root.get(), header);
    const std::vector<float> bands(kBandCentreHz.begin(), kBandCentreHz.end());
    h5::writeAttribute(root.get(), "fixed_crc32", uint64_t(fixedChecksum(header, bands)));
    h5::reserveFile(f);
    writeFixed(f, header);
    h5::flushToDevice(f);
  } catch (const std::runtime_error& e) {
    writeFailed(displayPath, "", e);
  }
  return BakeFile(std::move(impl));
}

BakeFile BakeFile::open(const std::string& path, Access access) {
  h5::silenceHdf5();
  // A folder, a FIFO or a device is named as such (not "no such file"), before HDF5 reads it.
  checkInputFile(path, std::numeric_limits<std::uintmax_t>::max(), path, "", "bake");
  checkHdf5Signature(path);
  auto impl = std::make_unique<Impl>();
  impl->path = impl->file = path;
  impl->load(access == Access::kWrite, access != Access::kWrite);
  if (access != Access::kRead) return BakeFile(std::move(impl));
  if (!impl->damaged.empty())
    throw InputError(path, "", impl->damageReport + " (the file is damaged: " +
                                   std::to_string(impl->damaged.size()) +
                                   " probes fail their checksums)");
  if (!impl->waveDamage.empty())
    throw InputError(path, "", impl->waveDamage + " (the file is damaged)");
  const bool complete = readComplete(impl->handle.get(), path);
  for (size_t s = 0; complete && s < impl->waveStored.size(); ++s)
    if (!impl->waveStored[s])
      throw InputError(path, kWaveDone,
                       "source " + std::to_string(s) + "'s wave band is not stored, yet the "
                                                      "file is marked complete");
  for (size_t p = 0; complete && p < impl->stored.size(); ++p)
    if (!impl->stored[p])
      throw InputError(path, "probes/done",
                       "probe " + std::to_string(p) + " is not stored, yet the file is marked "
                                                      "complete");
  return BakeFile(std::move(impl));
}

bool BakeFile::complete() const { return readComplete(impl_->handle.get(), impl_->path); }

void BakeFile::renamedTo(const std::string& path) { impl_->path = impl_->file = path; }

void BakeFile::markIncomplete() { impl_->writeComplete(0); }

void BakeFile::commit(size_t probe, const ProbeResult& result) {
  const auto start = std::chrono::steady_clock::now();
  const hid_t f = impl_->handle.get();
  std::string dataset;
  try {
    for (const ProbeDataset& d : kProbeDatasets) {
      dataset = d.name;
      h5::writeRows(f, d.name, H5T_NATIVE_FLOAT, probe, 1, (result.*d.member).data());
    }
    dataset = "checksums";
    const std::vector<uint32_t> sums = probeChecksums(result);
    h5::writeRows(f, "checksums", H5T_NATIVE_UINT32, probe, 1, sums.data());
    if (H5Fflush(f, H5F_SCOPE_GLOBAL) < 0) throw std::runtime_error(h5::lastError());
    dataset = "probes/done";
    const uint8_t one = 1;
    h5::writeRows(f, "probes/done", H5T_NATIVE_UINT8, probe, 1, &one);
    if (H5Fflush(f, H5F_SCOPE_GLOBAL) < 0) throw std::runtime_error(h5::lastError());
  } catch (const std::runtime_error& e) {
    writeFailed(impl_->path, dataset, e);
  }
  impl_->stored[probe] = 1;
  impl_->commitSeconds +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void BakeFile::commitWave(size_t source, const std::vector<float>& band,
                          const std::vector<uint8_t>& reached) {
  const hid_t f = impl_->handle.get();
  std::string dataset = kWaveBand;
  try {
    h5::writeRows(f, kWaveBand, H5T_NATIVE_FLOAT, source, 1, band.data());
    dataset = kWaveReached;
    h5::writeRows(f, kWaveReached, H5T_NATIVE_UINT8, source, 1, reached.data());
    dataset = kWaveChecksums;
    const uint32_t sum = waveChecksum(band, reached);
    h5::writeRows(f, kWaveChecksums, H5T_NATIVE_UINT32, source, 1, &sum);
    if (H5Fflush(f, H5F_SCOPE_GLOBAL) < 0) throw std::runtime_error(h5::lastError());
    dataset = kWaveDone;
    const uint8_t one = 1;
    h5::writeRows(f, kWaveDone, H5T_NATIVE_UINT8, source, 1, &one);
    if (H5Fflush(f, H5F_SCOPE_GLOBAL) < 0) throw std::runtime_error(h5::lastError());
  } catch (const std::runtime_error& e) {
    writeFailed(impl_->path, dataset, e);
  }
  impl_->waveStored[source] = 1;
}

void BakeFile::markComplete() {
  Impl& m = *impl_;
  try {
    h5::flushToDevice(m.handle.get());
    if (!m.handle.close()) throw std::runtime_error(h5::lastError());
  } catch (const std::runtime_error& e) {
    writeFailed(m.path, "", e);
  }
  m.load(false);  // afresh from the file: nothing cached by this process's HDF5
  if (!m.damaged.empty())
    throw InputError(m.path, "complete", "not marked complete: " + m.damageReport);
  if (!m.waveDamage.empty())
    throw InputError(m.path, "complete", "not marked complete: " + m.waveDamage);
  for (size_t s = 0; s < m.waveStored.size(); ++s)
    if (!m.waveStored[s])
      throw InputError(m.path, "complete",
                       "not marked complete: source " + std::to_string(s) +
                           "'s wave band is not stored");
  for (size_t p = 0; p < m.stored.size(); ++p)
    if (!m.stored[p])
      throw InputError(m.path, "complete",
                       "not marked complete: probe " + std::to_string(p) + " is not stored");
  m.handle.close();
  m.load(true, false);
  m.writeComplete(1);
}

namespace {

/// A whole dataset of `file` as `type` into a vector of T.
template <typename T>
std::vector<T> readWhole(hid_t file, const std::string& path, const std::string& dataset,
                         hid_t type) {
  size_t n = 1;
  try {
    for (const hsize_t d : h5::datasetDims(file, dataset)) n *= d;
  } catch (const std::runtime_error& e) {
    throw InputError(path, "/" + dataset, e.what());
  }
  std::vector<T> out(n);
  try {
    if (n > 0) h5::readAll(file, dataset, type, out.data());
  } catch (const std::runtime_error& e) {
    throw InputError(path, "", e.what());  // names the dataset
  }
  return out;
}

}  // namespace

std::vector<float> BakeFile::readAll(const std::string& dataset) const {
  return readWhole<float>(impl_->handle.get(), impl_->path, dataset, H5T_NATIVE_FLOAT);
}

std::vector<uint8_t> BakeFile::readBytes(const std::string& dataset) const {
  return readWhole<uint8_t>(impl_->handle.get(), impl_->path, dataset, H5T_NATIVE_UINT8);
}

}  // namespace dpc::bake
