// Integrity of a bake file (docs/bake-format.md, "Checksums"): a CRC-32 (zlib's) of every
// probe's row of every per-probe dataset, stored in /checksums when the probe is committed,
// and one of the datasets fixed at creation (probe and source positions, band centres) in the
// root attribute `fixed_crc32`. HDF5 checksums its own metadata (superblock and object
// headers of format 2), so with these every byte that carries data is covered.
// Control thread; allocates (one block of at most kVerifyBlockBytes per dataset); read errors
// as std::runtime_error naming the dataset.
#pragma once

#include <hdf5.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "bake/bake_layout.h"

namespace dpc::bake {

/// Largest block of rows read at once while verifying, bytes.
inline constexpr size_t kVerifyBlockBytes = 16u << 20;

/// CRC-32 of n floats as stored in the file (IEEE binary32, little endian).
uint32_t crc32Of(const float* data, size_t n);
/// The /checksums row of a probe's result: one CRC-32 per kProbeDatasets entry.
std::vector<uint32_t> probeChecksums(const ProbeResult& r);
/// CRC-32 of probes/position, sources/position (the header's) and band_centres_hz (`bands`),
/// in that order.
uint32_t fixedChecksum(const BakeHeader& h, const std::vector<float>& bands);

/// The kWaveChecksums entry of one source: CRC-32 of its kWaveBand row (`band`, probes x
/// samples floats) followed by its kWaveReached row (`reached`, one byte per probe).
uint32_t waveChecksum(const std::vector<float>& band, const std::vector<uint8_t>& reached);

/// The wave band's sources stored and verified (kWaveDone read, each done source's rows read
/// back against kWaveChecksums), and the first damaged one's problem ("" if none).
struct WaveVerification {
  std::vector<uint8_t> stored;
  std::vector<size_t> damaged;
  std::string firstProblem;
};
/// For a header whose wave layout is enabled; empty otherwise.
WaveVerification verifyWave(hid_t file, const BakeHeader& h);

struct Verification {
  /// Per probe: 1 where the done mask says stored and every row matches its checksum.
  std::vector<uint8_t> stored;
  /// Probes marked done (or with a done value other than 0 and 1) whose rows do not match.
  std::vector<size_t> damaged;
  /// What the first damaged probe's problem was ("/energy: probe 3: ..."), "" if none.
  std::string firstProblem;
};

/// Reads every row of every probe `done` marks (1) back from the file and compares its CRC-32
/// with /checksums; a done value other than 0 or 1 counts as damaged.
Verification verifyProbes(hid_t file, const BakeHeader& h, const std::vector<uint8_t>& done);

}  // namespace dpc::bake
