// Atomic output files: a temporary file in the destination folder, renamed into place only once
// complete. Shared by every writer of a user-named output (WAV files, the energy-response CSV)
// so that a failed or interrupted write never leaves a partial file at the path, and never
// touches a file that already exists there.
//
// Control thread or an offline render thread (never the audio thread): allocates, makes system
// calls and throws InputError(path, "", reason) naming the output path.
#pragma once

#include <fcntl.h>
#include <limits.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <initializer_list>
#include <string>
#include <utility>
#include <vector>

#include "common/input_error.h"
#include "common/input_file.h"

namespace dpc {

/// The folder holding `path` ("." for a bare file name).
inline std::string outputFolderOf(const std::string& path) {
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  return parent.empty() ? std::string(".") : parent.string();
}

/// What a temporary output file adds to its target's name (mkstemp's template).
inline constexpr char kTempOutputSuffix[] = ".tmp-XXXXXX";

/// Why `path` cannot name an output file, or "" if it can: its last component with the
/// temporary's suffix must fit the folder's file-name limit (pathconf, else NAME_MAX), and
/// the whole path PATH_MAX. Checked before any work: otherwise the first file-system call
/// fails with a bare "File name too long" that names neither the flag nor the field.
inline std::string outputNameProblem(const std::string& path) {
  const size_t suffix = sizeof(kTempOutputSuffix) - 1;
  long nameMax = ::pathconf(outputFolderOf(path).c_str(), _PC_NAME_MAX);
  if (nameMax <= 0) nameMax = NAME_MAX;
  const size_t name = std::filesystem::path(path).filename().string().size();
  if (name + suffix > size_t(nameMax))
    return "its file name of " + std::to_string(name) + " bytes is too long (at most " +
           std::to_string(size_t(nameMax) - suffix) + " for an output in this folder)";
  if (path.size() + suffix >= size_t(PATH_MAX))
    return "the path of " + std::to_string(path.size()) + " bytes is too long (at most " +
           std::to_string(size_t(PATH_MAX) - suffix - 1) + ")";
  return "";
}

/// Symbolic links followed from an output path before giving up (the kernel's own limit).
inline constexpr int kMaxOutputSymlinks = 40;

/// The file a write to `path` must replace: `path` itself, or where it leads if it is a
/// symbolic link (so that the link stays a link and its target gets the new contents), also
/// when the link dangles (the target is then created). Links are followed one at a time, a
/// relative one from its own folder. Throws InputError(path, "", ...) for a loop of links.
inline std::string outputTarget(const std::string& path) {
  std::filesystem::path p = path;
  for (int links = 0; links <= kMaxOutputSymlinks; ++links) {
    std::error_code ec;
    if (!std::filesystem::is_symlink(p, ec)) return p.string();
    const std::filesystem::path next = std::filesystem::read_symlink(p, ec);
    if (ec) return p.string();
    p = next.is_absolute() ? next : p.parent_path() / next;
  }
  throw InputError(path, "", "cannot write: too many levels of symbolic links");
}

/// Throws InputError(path, "", ...) if `target` exists and is not a regular file: renaming a
/// file onto a device (/dev/null), a FIFO or a folder would replace it, and run as root even
/// a device node.
inline void checkReplaceable(const std::string& path, const std::string& target) {
  struct stat st {};
  if (::stat(target.c_str(), &st) == 0 && !S_ISREG(st.st_mode))
    throw InputError(path, "", "cannot write: '" + target + "' exists and is not a regular file");
}

/// True if the existing file `st` describes (at `target`) must not be replaced: the user may
/// not write it (access), or nobody may (no write bit in its mode). The second holds also for
/// root, whom access() lets write anything: a file marked read-only (chmod 444) is protected
/// on purpose, and the rename of the temporary would replace it without a word.
inline bool isReadOnlyFile(const std::string& target, const struct stat& st) {
  return (st.st_mode & 0222) == 0 || ::access(target.c_str(), W_OK) != 0;
}

/// An output path checked before any work, as every program names its outputs: `flag` is the
/// option that named it ("--offline"), `inputs` the files of the run, each with what it is
/// ("the scene file"). Throws InputError("command line", flag, ...) unless the path (through
/// its symbolic links) is a regular file the user may write (isReadOnlyFile) or absent, names
/// none of the inputs (same device and inode), and lies in an existing, writable folder.
inline void checkOutputPath(const std::string& path, const std::string& flag,
                            const std::vector<std::pair<std::string, std::string>>& inputs) {
  std::string target;
  try {
    target = outputTarget(path);
  } catch (const InputError&) {
    throw InputError("command line", flag, "'" + path + "': too many levels of symbolic links");
  }
  if (const std::string why = outputNameProblem(target); !why.empty())
    throw InputError("command line", flag, why);
  struct stat st {};
  if (::stat(target.c_str(), &st) == 0 && !S_ISREG(st.st_mode))
    throw InputError("command line", flag, "'" + path + "' exists and is not a regular file");
  for (const auto& [in, what] : inputs)
    if (sameFile(path, in))
      throw InputError("command line", flag,
                       "'" + path + "' is " + what + "; refusing to overwrite it");
  if (S_ISREG(st.st_mode) && isReadOnlyFile(target, st))
    throw InputError("command line", flag, "'" + path + "': cannot write: the file is read-only");
  const std::string folder = outputFolderOf(target);
  std::error_code ec;
  if (!std::filesystem::is_directory(folder, ec))
    throw InputError("command line", flag, "folder '" + folder + "' does not exist");
  // Mode bits as for a file (isReadOnlyFile): access() lets root write into a chmod 555 folder.
  struct stat folderStat {};
  if (::access(folder.c_str(), W_OK) != 0 ||
      (::stat(folder.c_str(), &folderStat) == 0 && (folderStat.st_mode & 0222) == 0))
    throw InputError("command line", flag, "folder '" + folder + "' is not writable");
}

/// The format a file name's extension names among those dpc reads and writes ("" for any
/// other extension, or none).
inline std::string formatOfName(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  static const std::pair<const char*, const char*> kKnown[] = {
      {".wav", "WAV"}, {".sofa", "SOFA"}, {".csv", "CSV"},   {".json", "JSON"},
      {".h5", "HDF5"}, {".obj", "OBJ"},   {".gltf", "glTF"}, {".glb", "glTF"}};
  for (const auto& [e, format] : kKnown)
    if (ext == e) return format;
  return "";
}

/// An output whose name names another format than its flag writes is refused (--ir-out
/// ir.csv wrote a WAV that dpc-analyze then read as CSV). Other extensions pass. Throws
/// InputError("command line", flag, ...).
inline void checkOutputFormat(const char* flag, const std::string& path,
                              std::initializer_list<std::string> writes) {
  const std::string named = formatOfName(path);
  if (path.empty() || named.empty() ||
      std::find(writes.begin(), writes.end(), named) != writes.end())
    return;
  std::string list;
  for (const std::string& w : writes) list += (list.empty() ? "" : " or ") + w;
  throw InputError("command line", flag,
                   "'" + path + "' names a " + named + " file, but " + flag + " writes " + list);
}

/// A temporary file TARGET.tmp-XXXXXX next to `path`'s target (outputTarget: `path`, or the
/// file a symbolic link at `path` leads to), created at construction (mode 0666 & ~umask, as
/// a new file would get), renamed onto the target by commit(). Until commit() succeeds, the
/// destructor closes and removes the temporary, so `path` is either untouched or complete.
class TempOutputFile {
 public:
  /// Creates the temporary. Throws InputError(path, "", ...) if the folder does not exist or a
  /// file cannot be created in it.
  explicit TempOutputFile(const std::string& path) : path_(path), target_(outputTarget(path)) {
    checkReplaceable(path, target_);
    const std::string folder = outputFolderOf(target_);
    std::error_code ec;
    if (!std::filesystem::is_directory(folder, ec))
      throw InputError(path, "", "cannot write: folder '" + folder + "' does not exist");
    // Next to the target, so that the final rename stays on one filesystem (atomic).
    tmp_ = target_ + kTempOutputSuffix;
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
  /// The moved-from file owns nothing (its destructor removes nothing).
  TempOutputFile(TempOutputFile&& o) noexcept
      : path_(std::move(o.path_)),
        target_(std::move(o.target_)),
        tmp_(std::exchange(o.tmp_, {})),
        fd_(std::exchange(o.fd_, -1)) {}

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

  /// Closes the descriptor if still owned, reporting a failed close (e.g. a delayed write
  /// error): the temporary is then complete, ready for rename(). Throws on failure; the
  /// temporary is then removed.
  void finish() {
    if (tmp_.empty()) fail("the file is already closed");
    if (fd_ >= 0) {
      const int rc = ::close(fd_);
      fd_ = -1;
      if (rc != 0) fail(std::string("closing the file failed: ") + std::strerror(errno));
    }
  }

  /// finish(), then renames the temporary to the path. Throws on failure; the temporary is
  /// then removed.
  void commit() {
    finish();
    if (std::rename(tmp_.c_str(), target_.c_str()) != 0)
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
  std::string path_, target_, tmp_;  ///< as given, the file replaced, the temporary
  int fd_ = -1;
};

/// checkOutputPath, then a temporary made and removed beside the target: a folder that
/// access() lets root write but that takes no file (/proc, a read-only mount) fails here,
/// before any work, not after it. Throws InputError("command line", flag, ...).
inline void checkOutputCreatable(const std::string& path, const std::string& flag,
                                 const std::vector<std::pair<std::string, std::string>>& inputs) {
  checkOutputPath(path, flag, inputs);
  try {
    TempOutputFile trial(path);
  } catch (const InputError& e) {
    throw InputError("command line", flag, e.what());
  }
}

/// The outputs of one run, all or nothing: finished temporaries collected while the run
/// writes, renamed into place together by commitAll() once every one is complete. Until
/// then (an error, a stop signal), the destructor removes them all and no path is touched.
class OutputSet {
 public:
  /// Takes a temporary (finished here if it is not yet). Throws as TempOutputFile::finish.
  void add(TempOutputFile&& file) {
    file.finish();
    files_.push_back(std::move(file));
  }
  /// Renames every temporary into place, in the order added. Throws on the first failure;
  /// the temporaries not yet renamed are then removed.
  void commitAll() {
    for (TempOutputFile& f : files_) f.commit();
    files_.clear();
  }

 private:
  std::vector<TempOutputFile> files_;
};

}  // namespace dpc
