// Shared by the fuzz targets: the loaders read files by path (they check that the input is a
// regular file of bounded size), so each input is written to a file in a private folder that
// also holds the repository's scene meshes, so that scene JSON naming them loads them.
#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>

namespace dpc::fuzz {

/// The private folder (created once per process, with copies of scenes/*.obj).
inline const std::filesystem::path& folder() {
  static const std::filesystem::path dir = [] {
    namespace fs = std::filesystem;
    fs::path d = fs::temp_directory_path() / ("dpc_fuzz_" + std::to_string(::getpid()));
    fs::create_directories(d);
    for (const auto& e : fs::directory_iterator(fs::path(DPC_SOURCE_DIR) / "scenes"))
      if (e.path().extension() == ".obj")
        fs::copy_file(e.path(), d / e.path().filename(), fs::copy_options::overwrite_existing);
    return d;
  }();
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
