// A test's own folder under the system's temporary folder, removed with all it holds when the
// TempDir goes.
#pragma once

#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <string>
#include <system_error>

namespace dpc::test {

class TempDir {
 public:
  /// Makes <temp>/<prefix>_<pid>_<n>, n counting the TempDirs this process has made.
  explicit TempDir(const std::string& prefix) : path_(uniquePath(prefix)) {
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ignored;  // nothing to do about a folder that will not go
    std::filesystem::remove_all(path_, ignored);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::filesystem::path& path() const { return path_; }

 private:
  static std::filesystem::path uniquePath(const std::string& prefix) {
    static std::atomic<int> made{0};
    return std::filesystem::temp_directory_path() /
           (prefix + "_" + std::to_string(::getpid()) + "_" + std::to_string(made++));
  }

  std::filesystem::path path_;
};

}  // namespace dpc::test
