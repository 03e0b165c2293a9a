// Atomic output files: a temporary file in the destination folder, renamed into place only once
// complete. Shared by every writer of a user-named output (WAV files, the energy-response CSV)
// so that a failed or interrupted write never leaves a partial file at the path, and never
// touches a file that already exists there.
//
// Control thread or an offline render thread (never the audio thread): allocates, makes system
// calls and throws InputError(path, "", reason) naming the output path.
#pragma once

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>

#include "common/input_error.h"

namespace dpc {

/// The folder holding `path` ("." for a bare file name).
inline std::string outputFolderOf(const std::string& path) {
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  return parent.empty() ? std::string(".") : parent.string();
}

/// A temporary file PATH.tmp-XXXXXX next to `path`, created at construction (mode 0666 & ~umask,
/// as a new file would get), renamed to `path` by commit(). Until commit() succeeds, the
/// destructor closes and removes the temporary, so `path` is either untouched or complete.
class TempOutputFile {
 public:
  /// Creates the temporary. Throws InputError(path, "", ...) if the folder does not exist or a
  /// file cannot be created in it.
  explicit TempOutputFile(const std::string& path) : path_(path) {
    const std::string folder = outputFolderOf(path);
    std::error_code ec;
    if (!std::filesystem::is_directory(folder, ec))
      throw InputError(path, "", "cannot write: folder '" + folder + "' does not exist");
    // Next to the target, so that the final rename stays on one filesystem (atomic).
    tmp_ = path + ".tmp-XXXXXX";
    fd_ = ::mkstemp(tmp_.data());
    if (fd_ < 0) {
      const int err = errno;
      tmp_.clear();
      throw InputError(path, "", "cannot write in folder '" + folder + "': " + std::strerror(err));
    }
    const mode_t mask = ::umask(0);
    ::umask(mask);
    ::fchmod(fd_, 0666 & ~mask);
  }
  ~TempOutputFile() { discard(); }
  TempOutputFile(const TempOutputFile&) = delete;
  TempOutputFile& operator=(const TempOutputFile&) = delete;

  const std::string& path() const { return path_; }
  const std::string& tempPath() const { return tmp_; }
  /// The open descriptor of the temporary, or -1 once closed or released.
  int fd() const { return fd_; }
  /// Hands the descriptor to another owner (e.g. libsndfile's sf_open_fd with close_desc), which
  /// then closes it; the temporary's name is still removed unless committed.
  int releaseFd() {
    const int fd = fd_;
    fd_ = -1;
    return fd;
  }

  /// Writes all `size` bytes at the current offset (retrying short writes and EINTR). Throws
  /// (and removes the temporary) on failure, e.g. a full disk or a file-size limit.
  void writeAll(const void* data, size_t size) {
    if (fd_ < 0) fail("the file is already closed");
    const char* p = static_cast<const char*>(data);
    while (size > 0) {
      const ssize_t n = ::write(fd_, p, size);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) fail(n < 0 ? std::strerror(errno) : "nothing written");
      p += n;
      size -= size_t(n);
    }
  }

  /// Closes the descriptor if still owned (reporting a failed close, e.g. a delayed write error)
  /// and renames the temporary to the path. Throws on failure; the temporary is then removed.
  void commit() {
    if (tmp_.empty()) fail("the file is already closed");
    if (fd_ >= 0) {
      const int rc = ::close(fd_);
      fd_ = -1;
      if (rc != 0) fail(std::string("closing the file failed: ") + std::strerror(errno));
    }
    if (std::rename(tmp_.c_str(), path_.c_str()) != 0)
      fail(std::string("renaming the temporary file failed: ") + std::strerror(errno));
    tmp_.clear();  // now the output itself: nothing to remove
  }

  /// Closes and removes the temporary (no-op after commit() or a previous discard()).
  void discard() noexcept {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
    if (!tmp_.empty()) std::remove(tmp_.c_str());
    tmp_.clear();
  }

  /// Removes the temporary and throws InputError(path, "", "cannot write: " + reason).
  [[noreturn]] void fail(const std::string& reason) {
    discard();
    throw InputError(path_, "", "cannot write: " + reason);
  }

 private:
  std::string path_, tmp_;
  int fd_ = -1;
};

}  // namespace dpc
