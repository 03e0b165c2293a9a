#include "bake/bake_verify.h"

#include <zlib.h>

#include <algorithm>
#include <bit>
#include <cstdio>

#include "bake/hdf5_util.h"

namespace dpc::bake {

static_assert(std::endian::native == std::endian::little,
              "the checksums are of the file's little-endian bytes");

uint32_t crc32Of(const float* data, size_t n) {
  uLong crc = crc32(0L, Z_NULL, 0);
  const auto* bytes = reinterpret_cast<const Bytef*>(data);
  size_t left = n * sizeof(float);
  while (left > 0) {  // zlib takes at most 4 GB a call
    const uInt part = uInt(std::min<size_t>(left, 1u << 30));
    crc = crc32(crc, bytes, part);
    bytes += part;
    left -= part;
  }
  return uint32_t(crc);
}

std::vector<uint32_t> probeChecksums(const ProbeResult& r) {
  std::vector<uint32_t> out;
  for (const ProbeDataset& d : kProbeDatasets)
    out.push_back(crc32Of((r.*d.member).data(), (r.*d.member).size()));
  return out;
}

uint32_t waveChecksum(const std::vector<float>& band, const std::vector<uint8_t>& reached) {
  uLong crc = crc32Of(band.data(), band.size());
  return uint32_t(crc32(crc, reinterpret_cast<const Bytef*>(reached.data()), uInt(reached.size())));
}

uint32_t fixedChecksum(const BakeHeader& h, const std::vector<float>& bands) {
  std::vector<float> all;
  for (const glm::vec3& p : h.probes.positions) all.insert(all.end(), {p.x, p.y, p.z});
  for (const glm::vec3& s : h.sources) all.insert(all.end(), {s.x, s.y, s.z});
  all.insert(all.end(), bands.begin(), bands.end());
  return crc32Of(all.data(), all.size());
}

namespace {

std::string hex(uint32_t v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%08x", v);
  return buf;
}

/// Marks probe p damaged with its problem (called once per probe: a damaged probe is no
/// longer stored, so it is not checked again).
void damage(Verification& v, size_t p, const std::string& problem) {
  v.stored[p] = 0;
  v.damaged.push_back(p);
  if (v.firstProblem.empty()) v.firstProblem = problem;
}

/// Checks dataset k's rows of every stored probe against column k of `sums` ([P][K]).
void verifyDataset(hid_t file, const BakeHeader& h, size_t k, const std::vector<uint32_t>& sums,
                   Verification& v) {
  const ProbeDataset& d = kProbeDatasets[k];
  const size_t probes = h.probes.positions.size(), row = rowFloats(d, h.shape);
  const size_t block = std::max<size_t>(1, kVerifyBlockBytes / std::max<size_t>(1, row * 4));
  std::vector<float> data;
  for (size_t first = 0; first < probes; first += block) {
    const size_t rows = std::min(block, probes - first);
    if (std::none_of(v.stored.begin() + std::ptrdiff_t(first),
                     v.stored.begin() + std::ptrdiff_t(first + rows), [](uint8_t s) { return s; }))
      continue;
    data.resize(rows * row);
    h5::readRows(file, d.name, H5T_NATIVE_FLOAT, first, rows, data.data());
    for (size_t i = 0; i < rows; ++i) {
      const size_t p = first + i;
      if (!v.stored[p]) continue;
      const uint32_t got = crc32Of(data.data() + i * row, row);
      const uint32_t want = sums[p * kProbeDatasets.size() + k];
      if (got != want)
        damage(v, p,
               "/" + std::string(d.name) + ": probe " + std::to_string(p) + ": CRC-32 " +
                   hex(got) + ", /checksums holds " + hex(want));
    }
  }
}

}  // namespace

WaveVerification verifyWave(hid_t file, const BakeHeader& h) {
  WaveVerification v;
  if (!h.wave.enabled) return v;
  const size_t sources = h.sources.size(), probes = h.probes.positions.size();
  std::vector<uint8_t> done(sources);
  std::vector<uint32_t> sums(sources);
  h5::readAll(file, kWaveDone, H5T_NATIVE_UINT8, done.data());
  h5::readAll(file, kWaveChecksums, H5T_NATIVE_UINT32, sums.data());
  v.stored.assign(sources, 0);
  std::vector<float> band(probes * h.wave.samples);
  std::vector<uint8_t> reached(probes);
  for (size_t s = 0; s < sources; ++s) {
    if (done[s] == 0) continue;
    std::string problem;
    if (done[s] == 1) {
      h5::readRows(file, kWaveBand, H5T_NATIVE_FLOAT, s, 1, band.data());
      h5::readRows(file, kWaveReached, H5T_NATIVE_UINT8, s, 1, reached.data());
      const uint32_t got = waveChecksum(band, reached);
      if (got == sums[s]) {
        v.stored[s] = 1;
        continue;
      }
      problem = "/" + std::string(kWaveBand) + ": source " + std::to_string(s) + ": CRC-32 " +
                hex(got) + ", /" + kWaveChecksums + " holds " + hex(sums[s]);
    } else {
      problem = "/" + std::string(kWaveDone) + ": source " + std::to_string(s) + ": value " +
                std::to_string(done[s]) + " (0 or 1 expected)";
    }
    v.damaged.push_back(s);
    if (v.firstProblem.empty()) v.firstProblem = problem;
  }
  return v;
}

Verification verifyProbes(hid_t file, const BakeHeader& h, const std::vector<uint8_t>& done) {
  const size_t probes = h.probes.positions.size();
  Verification v;
  v.stored.assign(probes, 0);
  for (size_t p = 0; p < probes; ++p) v.stored[p] = done[p] == 1;
  for (size_t p = 0; p < probes; ++p)
    if (done[p] > 1)
      damage(v, p, "/probes/done: probe " + std::to_string(p) + ": value " +
                       std::to_string(done[p]) + " (0 or 1 expected)");
  std::vector<uint32_t> sums(probes * kProbeDatasets.size());
  h5::readAll(file, "checksums", H5T_NATIVE_UINT32, sums.data());
  for (size_t k = 0; k < kProbeDatasets.size(); ++k) verifyDataset(file, h, k, sums, v);
  std::sort(v.damaged.begin(), v.damaged.end());
  return v;
}

}  // namespace dpc::bake
