// Shared by the fuzz targets: the loaders read files by path (they check that the input is a
// regular file of bounded size), so each input is written to a file in a private folder that
// also holds the repository's scene meshes and dry signals, so that scene JSON naming them
// loads them.
#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

namespace dpc::fuzz {

/// The private folder (created once per process, with copies of scenes/*.obj and
/// scenes/signals/*.wav).
inline const std::filesystem::path& folder() {
  static const std::filesystem::path dir = [] {
    namespace fs = std::filesystem;
    fs::path d = fs::temp_directory_path() / ("dpc_fuzz_" + std::to_string(::getpid()));
    fs::create_directories(d);
    const fs::path scenes = fs::path(DPC_SOURCE_DIR) / "scenes";
    for (const auto& e : fs::directory_iterator(scenes))
      if (e.path().extension() == ".obj")
        fs::copy_file(e.path(), d / e.path().filename(), fs::copy_options::overwrite_existing);
    // The dry signals the shipped scenes name (the loader checks that they exist).
    fs::create_directories(d / "signals");
    for (const auto& e : fs::directory_iterator(scenes / "signals"))
      if (e.path().extension() == ".wav")
        fs::copy_file(e.path(), d / "signals" / e.path().filename(),
                      fs::copy_options::overwrite_existing);
    return d;
  }();
  static const bool cleanup = [] {
    std::atexit([] {
      std::error_code ec;
      std::filesystem::remove_all(folder(), ec);
    });
    return true;
  }();
  (void)cleanup;
  return dir;
}

/// Writes `data` to NAME in the private folder and returns its path.
inline std::string put(const std::string& name, const uint8_t* data, size_t size) {
  const std::string path = (folder() / name).string();
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) std::abort();
  if (size && std::fwrite(data, 1, size, f) != size) std::abort();
  std::fclose(f);
  return path;
}

}  // namespace dpc::fuzz
