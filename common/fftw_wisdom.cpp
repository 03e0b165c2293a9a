#include "common/fftw_wisdom.h"

#include <fftw3.h>

#include <cstdlib>
#include <filesystem>
#include <memory>

#include "common/output_file.h"

namespace dpc {

namespace {

/// The wisdom as last read from or written to the file by this process.
std::string& lastWisdom() {
  static std::string wisdom;
  return wisdom;
}

std::string currentWisdom() {
  std::unique_ptr<char, void (*)(void*)> text(fftwf_export_wisdom_to_string(), std::free);
  return text ? std::string(text.get()) : std::string();
}

}  // namespace

std::string fftwWisdomPath() {
  if (const char* own = std::getenv("DPC_FFTW_WISDOM")) return own;
  if (const char* cache = std::getenv("XDG_CACHE_HOME"); cache && *cache)
    return std::string(cache) + "/dpc/fftw-wisdom";
  if (const char* home = std::getenv("HOME"); home && *home)
    return std::string(home) + "/.cache/dpc/fftw-wisdom";
  return "";
}

void importFftwWisdomOnce() {
  static bool done = false;
  if (done) return;
  done = true;
  const std::string path = fftwWisdomPath();
  if (!path.empty() && fftwf_import_wisdom_from_filename(path.c_str()) != 0)
    lastWisdom() = currentWisdom();
}

bool exportFftwWisdom() {
  const std::string path = fftwWisdomPath();
  if (path.empty()) return false;
  const std::string wisdom = currentWisdom();
  if (wisdom.empty() || wisdom == lastWisdom()) return !wisdom.empty();
  try {
    std::error_code ec;
    std::filesystem::create_directories(std::filesystem::path(path).parent_path(), ec);
    TempOutputFile file(path);
    file.writeAll(wisdom.data(), wisdom.size());
    file.commit();
  } catch (const std::exception&) {
    return false;  // a cache: the next run measures again
  }
  lastWisdom() = wisdom;
  return true;
}

}  // namespace dpc
