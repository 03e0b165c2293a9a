// Input and output file checks shared by the loaders and the apps (control thread; may throw
// InputError; allocate only for messages). See docs/scene-format.md, "Limits".
#pragma once

#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "common/input_error.h"

namespace dpc {

/// Size bounds of input files in bytes (a scene's JSON, its OBJ mesh, a dry WAV, a SOFA file).
inline constexpr std::uintmax_t kMaxSceneBytes = 16u << 20;
inline constexpr std::uintmax_t kMaxMeshBytes = 512u << 20;
inline constexpr std::uintmax_t kMaxSignalBytes = 2048u << 20;
inline constexpr std::uintmax_t kMaxSofaBytes = 256u << 20;
/// An energy-response CSV (dpc-demo --er-out): 256 sources of 60 s in 1 ms bins stay below.
inline constexpr std::uintmax_t kMaxEnergyCsvBytes = 2048u << 20;
/// Largest nesting depth of arrays/objects accepted in a scene's JSON (the parser recurses).
inline constexpr int kMaxJsonDepth = 64;
/// Sample rates accepted for a dry signal, Hz: below 8 kHz even speech loses its band; the
/// ratio to any scene rate (16-192 kHz) then stays within the resampler's range [1/256, 256].
inline constexpr int kMinSignalRateHz = 8000;
inline constexpr int kMaxSignalRateHz = 768000;
/// Largest |sample| accepted in a dry signal (120 dB above full scale): with the largest
/// gain (+200 dB) and a long impulse response the render stays far inside float's range, so
/// that a wild signal is refused naming itself instead of overflowing the output.
inline constexpr float kMaxSignalMagnitude = 1e6f;

/// The problem with a dry-signal sample, "" if none: "is not finite (NaN or infinity)" or
/// "is 1e+38, beyond +-1e+06 (120 dB above full scale)". Any thread; allocates the text only
/// for a problem.
inline std::string sampleProblem(float x) {
  if (!std::isfinite(x)) return "is not finite (NaN or infinity)";
  if (std::abs(x) <= kMaxSignalMagnitude) return {};
  char text[96];
  std::snprintf(text, sizeof text, "is %g, beyond +-%g (120 dB above full scale)", double(x),
                double(kMaxSignalMagnitude));
  return text;
}

/// Largest |coordinate| accepted in a scene, metres (keeps Embree's rays valid in float).
inline constexpr double kMaxCoordinateM = 1e6;

/// Throws InputError(reportFile, field, ...) unless `path` names an existing regular file (after
/// symlinks) of at most maxBytes: FIFOs, devices and directories are refused before any read.
inline void checkInputFile(const std::string& path, std::uintmax_t maxBytes,
                           const std::string& reportFile, const std::string& field,
                           const std::string& what) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0)
    throw InputError(reportFile, field,
                     what + " '" + path + "' " +
                         (errno == ENOENT ? std::string("not found")
                                          : std::string("cannot be opened: ") + std::strerror(errno)));
  if (S_ISDIR(st.st_mode))
    throw InputError(reportFile, field, what + " '" + path + "' is a directory");
  if (!S_ISREG(st.st_mode))
    throw InputError(reportFile, field,
                     what + " '" + path + "' is not a regular file (FIFO, device or socket)");
  if (std::uintmax_t(st.st_size) > maxBytes)
    throw InputError(reportFile, field,
                     what + " '" + path + "' is " + std::to_string(st.st_size >> 20) +
                         " MiB, more than the limit of " + std::to_string(maxBytes >> 20) + " MiB");
}

/// True when a and b name the same existing file (same device and inode, symlinks followed).
inline bool sameFile(const std::string& a, const std::string& b) {
  struct stat sa {
  }, sb{};
  return ::stat(a.c_str(), &sa) == 0 && ::stat(b.c_str(), &sb) == 0 && sa.st_dev == sb.st_dev &&
         sa.st_ino == sb.st_ino;
}

/// Levenshtein distance between two names (insertions, deletions, substitutions), for the
/// "did you mean" hints on unknown scene keys and mistyped flags.
inline size_t editDistance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diag = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}

}  // namespace dpc
