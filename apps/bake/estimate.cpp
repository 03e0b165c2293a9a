#include "apps/bake/estimate.h"

#include <sys/statvfs.h>

#include <cstdio>

#include "bake/bake_layout.h"
#include "common/input_error.h"
#include "common/output_file.h"

namespace dpc::bake {
namespace {

std::string bytesText(double b) {
  char buf[32];
  if (b >= 1e9)
    std::snprintf(buf, sizeof buf, "%.1f GB", b / 1e9);
  else if (b >= 1e6)
    std::snprintf(buf, sizeof buf, "%.1f MB", b / 1e6);
  else
    std::snprintf(buf, sizeof buf, "%.0f kB", b / 1e3);
  return buf;
}

std::string secondsText(double s) {
  char buf[32];
  if (s >= 2 * 86400.0)
    std::snprintf(buf, sizeof buf, "%.1f days", s / 86400.0);
  else if (s >= 2 * 3600.0)
    std::snprintf(buf, sizeof buf, "%.1f h", s / 3600.0);
  else if (s >= 120.0)
    std::snprintf(buf, sizeof buf, "%.0f min", s / 60.0);
  else
    std::snprintf(buf, sizeof buf, "%.0f s", s);
  return buf;
}

}  // namespace

double bakeFileBytes(size_t probes, const ProbeShape& shape) {
  double perProbe = 3.0 * 4.0 + 1.0 + double(kProbeDatasets.size()) * 4.0;  // position, done, CRCs
  for (const ProbeDataset& d : kProbeDatasets) perProbe += double(rowFloats(d, shape)) * 4.0;
  return double(probes) * perProbe + double(shape.sources) * 12.0 + kMetadataBytes;
}

double waveBandBytes(size_t probes, size_t sources, const WaveLayout& wave) {
  if (!wave.enabled) return 0.0;
  // The band (floats), the reached mask (a byte a probe), done and CRC-32 per source.
  return double(sources) * (double(probes) * (double(wave.samples) * 4.0 + 1.0) + 5.0);
}

BakeEstimate estimateBake(size_t probes, size_t fileProbes, const ProbeShape& shape,
                          const BakeSettings& settings, double frameSeconds, int processes) {
  BakeEstimate e;
  e.probes = probes;
  e.bytes = bakeFileBytes(fileProbes, shape);
  e.frameSeconds = frameSeconds;
  e.processes = processes;
  e.seconds = double(probes) * double(settings.frames) * frameSeconds / double(processes);
  return e;
}

std::string describe(const BakeEstimate& e) {
  char frame[64];
  std::snprintf(frame, sizeof frame, "%.3g s per frame measured", e.frameSeconds);
  const std::string up = e.upperBound ? "up to " : "";
  return up + std::to_string(e.probes) + " probes, a file of " + up + bytesText(e.bytes) +
         ", " + up + "about " + secondsText(e.seconds) + " on " +
         std::to_string(e.processes) + (e.processes > 1 ? " processes" : " process") + " (" +
         frame + ")";
}

std::string describe(const WaveEstimate& e) {
  char text[160];
  std::snprintf(text, sizeof text,
                "%zu simulation%s of a %d x %d x %d grid for %zu steps (%.2g node updates)",
                e.simulations, e.simulations == 1 ? "" : "s", e.count[0], e.count[1], e.count[2],
                e.steps, double(e.simulations) * double(e.nodes) * double(e.steps));
  return text;
}

void checkLimits(const BakeEstimate& e, bool force, const std::string& flag) {
  if (force) return;
  if (e.probes <= kMaxProbesUnforced && e.bytes <= kMaxBytesUnforced &&
      e.seconds <= kMaxSecondsUnforced)
    return;
  throw InputError("command line", flag,
                   describe(e) + ": over the limits of " + std::to_string(kMaxProbesUnforced) +
                       " probes, " + bytesText(kMaxBytesUnforced) + " and " +
                       secondsText(kMaxSecondsUnforced) +
                       " (docs/bake.md); a coarser grid, or --force to bake it anyway");
}

void checkFreeSpace(const std::string& path, double bytes, bool force) {
  if (force) return;
  struct statvfs fs {};
  if (::statvfs(outputFolderOf(outputTarget(path)).c_str(), &fs) != 0) return;
  const double available = double(fs.f_bavail) * double(fs.f_frsize);
  if (bytes > available)
    throw InputError(path, "",
                     "cannot write: the bake needs " + bytesText(bytes) + ", the file system has " +
                         bytesText(available) + " free (--force to try anyway)");
}

}  // namespace dpc::bake
