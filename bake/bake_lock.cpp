#include "bake/bake_lock.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>

#include "common/input_error.h"
#include "common/output_file.h"

namespace dpc::bake {
namespace {

/// The pid written in an open lock file, 0 when unreadable.
long pidIn(int fd) {
  char buf[32] = {};
  const ssize_t n = ::pread(fd, buf, sizeof buf - 1, 0);
  return n > 0 ? std::strtol(buf, nullptr, 10) : 0;
}

/// Whether fd is still the file at `path` (not unlinked by a writer that released it).
bool stillThere(int fd, const std::string& path) {
  struct stat a {}, b {};
  return ::fstat(fd, &a) == 0 && ::stat(path.c_str(), &b) == 0 && a.st_dev == b.st_dev &&
         a.st_ino == b.st_ino;
}

}  // namespace

std::string BakeLock::lockPath(const std::string& bakePath) {
  return outputTarget(bakePath) + ".lock";
}

BakeLock::BakeLock(const std::string& bakePath) : path_(lockPath(bakePath)) {
  // A writer releasing the lock unlinks the file first: retry on the new file if ours is gone.
  for (int attempt = 0; attempt < 100; ++attempt) {
    fd_ = ::open(path_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd_ < 0)
      throw InputError(bakePath, "", "cannot create the lock file '" + path_ +
                                         "': " + std::strerror(errno));
    if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
      const long pid = pidIn(fd_);
      ::close(fd_);
      fd_ = -1;
      throw InputError(bakePath, "",
                       "another dpc-bake" +
                           (pid > 0 ? " (pid " + std::to_string(pid) + ")" : std::string()) +
                           " is writing this bake (lock '" + path_ +
                           "'); one writer per file: wait for it, or stop it");
    }
    if (stillThere(fd_, path_)) break;
    ::close(fd_);
    fd_ = -1;
  }
  if (fd_ < 0) throw InputError(bakePath, "", "cannot take the lock file '" + path_ + "'");
  const std::string pid = std::to_string(::getpid()) + "\n";
  if (::ftruncate(fd_, 0) != 0 || ::pwrite(fd_, pid.data(), pid.size(), 0) < 0) {
    // The pid is only for messages; the lock itself holds.
  }
}

BakeLock::~BakeLock() {
  if (fd_ < 0) return;
  ::unlink(path_.c_str());  // before the release: a waiting writer then sees the file gone
  ::close(fd_);
}

long BakeLock::holder(const std::string& bakePath) {
  const std::string path = lockPath(bakePath);
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return 0;
  long pid = 0;
  if (::flock(fd, LOCK_SH | LOCK_NB) == 0)
    ::flock(fd, LOCK_UN);
  else
    pid = std::max(pidIn(fd), 1L);
  ::close(fd);
  return pid == long(::getpid()) ? 0 : pid;  // this process's own lock is no other writer
}

}  // namespace dpc::bake
