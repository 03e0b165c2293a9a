/* A full disk in the middle of a bake, where a small tmpfs cannot give one: dpc-bake allocates
 * its whole file when it creates it, so once created it only overwrites bytes the file system
 * already holds, which tmpfs (and ext4, xfs) never refuse. Copy-on-write file systems (btrfs,
 * ZFS) and quotas can still refuse such a write. Preloaded (LD_PRELOAD), this makes pwrite()
 * fail with ENOSPC once more than DPC_ENOSPC_AFTER bytes were written to files whose path
 * contains DPC_ENOSPC_NAME, as such a file system would. tests/apps/disk_full_test.sh uses it.
 */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/types.h>
#include <unistd.h>

static unsigned long long written;

static int watched(int fd) {
  const char* name = getenv("DPC_ENOSPC_NAME");
  char link[64], path[4096];
  if (!name || !*name) return 0;
  snprintf(link, sizeof link, "/proc/self/fd/%d", fd);
  const ssize_t n = readlink(link, path, sizeof path - 1);
  if (n <= 0) return 0;
  path[n] = '\0';
  return strstr(path, name) != NULL;
}

ssize_t pwrite(int fd, const void* buf, size_t count, off_t offset) {
  static ssize_t (*real)(int, const void*, size_t, off_t);
  if (!real) real = (ssize_t(*)(int, const void*, size_t, off_t))dlsym(RTLD_NEXT, "pwrite");
  if (watched(fd)) {
    const char* after = getenv("DPC_ENOSPC_AFTER");
    if (after && written + count > strtoull(after, NULL, 10)) {
      errno = ENOSPC;
      return -1;
    }
    written += count;
  }
  return real(fd, buf, count, offset);
}
