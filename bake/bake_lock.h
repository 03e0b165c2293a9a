// One writer per bake file: an advisory lock (flock, exclusive, never waited for) on
// "<bake>.lock" beside the file a write would replace (the bake itself, or where its symbolic
// links lead: outputTarget, common/output_file.h), taken before the bake is created or opened
// for writing and held until the writer is done. A second writer of the same file, through
// any name or link, is refused at once with one line naming the file and the pid that holds
// the lock. The lock file holds that pid; it is removed when the lock is released, and one
// left by a writer that was killed (SIGKILL) is simply taken over (the kernel released its
// lock with the process).
// Control thread; system calls; errors as InputError naming the bake.
#pragma once

#include <string>

namespace dpc::bake {

class BakeLock {
 public:
  /// Takes the lock for writing the bake at `bakePath`. Throws InputError(bakePath, "", ...)
  /// when another process holds it, or when the lock file cannot be created.
  explicit BakeLock(const std::string& bakePath);
  ~BakeLock();
  BakeLock(const BakeLock&) = delete;
  BakeLock& operator=(const BakeLock&) = delete;

  /// The lock file of the bake at `bakePath`.
  static std::string lockPath(const std::string& bakePath);
  /// The pid of another process writing the bake at `bakePath` (holding its lock), 0 when
  /// none (or when this process holds it).
  static long holder(const std::string& bakePath);

 private:
  std::string path_;
  int fd_ = -1;
};

}  // namespace dpc::bake
