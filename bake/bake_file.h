// The bake file: HDF5 (Debian libhdf5-dev, the C API), one writer. docs/bake-format.md
// describes every dataset, shape, unit and attribute; this is its one reader and writer.
//
// Every dataset is allocated and filled when the file is created, so a bake's writes only
// overwrite bytes already in the file: a disk too small fails the creation, before any probe.
// Crash consistency: a probe is committed by writing its rows of every per-probe dataset and
// their CRC-32s (/checksums), flushing, then setting its entry of /probes/done and flushing
// again, so a bake killed at any point leaves a file whose done mask names only probes whose
// rows are stored. The root attribute `complete` becomes 1 only after the file was flushed to
// the device (fsync), closed, opened afresh and every probe read back and checked.
// Opening verifies: the format, version, settings hashes and shapes, the fixed datasets'
// CRC-32, and every stored probe's rows against their CRC-32s (bake/bake_verify.h); for
// reading, any damage is refused, and so is a file marked complete with a probe not stored.
// Control thread of the writing process only; allocates; every error is an InputError naming
// the file and the dataset or attribute (a truncated, damaged or foreign file, a shape that
// does not match the header, a failed write with the system's reason).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "bake/bake_layout.h"

namespace dpc::bake {

class BakeFile {
 public:
  /// kRead: read only; a damaged probe or a complete file with a probe missing is refused.
  /// kInspect: read only; damaged probes are reported by damaged() and count as not done.
  /// kWrite: read and write, the probes' data not verified (the writer inspected the file
  /// before, holding its lock: bake/bake_lock.h); done() is the file's mask.
  enum class Access { kRead, kInspect, kWrite };

  /// Creates `path` (truncating it) with every dataset sized and filled for the header, no
  /// probe done, `complete` 0, flushed to the device. Messages name the file `displayPath`
  /// (e.g. the name a temporary file is renamed to).
  static BakeFile create(const std::string& path, const std::string& displayPath,
                         const BakeHeader& header);
  /// Opens an existing bake and verifies it (above; kWrite: all but the probes' data).
  static BakeFile open(const std::string& path, Access access);
  /// The file was renamed to `path` (from the temporary it was created at, or a complete
  /// X.partial onto X): messages name it and markComplete() reopens it there.
  void renamedTo(const std::string& path);

  BakeFile(BakeFile&&) noexcept;
  BakeFile& operator=(BakeFile&&) noexcept;
  ~BakeFile();

  const BakeHeader& header() const;
  const std::string& path() const;
  /// Per probe: 1 where its data are stored and were verified (on open, or committed since).
  const std::vector<uint8_t>& done() const;
  /// Probes the file marked done whose data failed verification on open (kInspect; sorted).
  const std::vector<size_t>& damaged() const;
  /// The first damaged probe's problem ("/energy: probe 3: CRC-32 ..."), "" if none.
  const std::string& damageReport() const;
  bool complete() const;
  /// Sets `complete` to 0 and flushes to the device (kWrite: before damaged probes are baked
  /// again).
  void markIncomplete();

  /// Writes probe `probe`'s arrays and checksums, flushes, marks it done and flushes.
  void commit(size_t probe, const ProbeResult& result);
  /// Per source: 1 where its wave band is stored and verified (header().wave.enabled; else
  /// empty). A source whose stored rows fail their checksum counts as not stored (kInspect),
  /// its problem in waveDamageReport(); kRead refuses it.
  const std::vector<uint8_t>& waveDone() const;
  const std::string& waveDamageReport() const;
  /// Writes source `source`'s wave band ([probes][samples] floats, docs/bake-format.md) and
  /// its reached mask ([probes]: 1 where the probe lies in the air its grid reaches) with
  /// their checksum, flushes, marks the source done and flushes.
  void commitWave(size_t source, const std::vector<float>& band,
                  const std::vector<uint8_t>& reached);
  /// Wall time spent in commit() so far, seconds (the writer's share of a bake's cost).
  double commitSeconds() const;
  /// Flushes to the device, reopens the file, verifies every probe and only then sets
  /// `complete` to 1 (flushed to the device again). Throws InputError naming the first probe
  /// not stored or damaged, leaving `complete` 0.
  void markComplete();

  /// A whole float dataset (e.g. "parameters"), row-major as documented.
  std::vector<float> readAll(const std::string& dataset) const;
  /// A whole uint8 dataset (e.g. "wave/reached").
  std::vector<uint8_t> readBytes(const std::string& dataset) const;

 private:
  struct Impl;
  explicit BakeFile(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace dpc::bake
