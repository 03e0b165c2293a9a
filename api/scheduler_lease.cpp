#include "api/scheduler_lease.h"

#include <tbb/global_control.h>

#include <mutex>
#include <new>

namespace dpc::api {

namespace {

/// The leases alive and the handle the first of them took; guarded by leaseMutex().
struct Leases {
  int count = 0;
  tbb::task_scheduler_handle handle;
};

std::mutex& leaseMutex() {
  static std::mutex m;
  return m;
}

/// Never destroyed: an engine may outlive the library's static objects at exit.
Leases& leases() {
  static Leases* l = new Leases;
  return *l;
}

}  // namespace

SchedulerLease::SchedulerLease() {
  std::lock_guard lock(leaseMutex());
  Leases& l = leases();
  if (l.count++ == 0) l.handle = tbb::task_scheduler_handle{tbb::attach{}};
}

SchedulerLease::~SchedulerLease() {
  std::lock_guard lock(leaseMutex());
  Leases& l = leases();
  // false: TBB is still used outside dpc's engines; its workers stay, as without dpc.
  if (--l.count == 0) (void)tbb::finalize(l.handle, std::nothrow);
}

}  // namespace dpc::api
