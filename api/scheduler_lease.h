// The C API's hold on TBB's worker threads. Every dpc_engine holds a lease from before its
// scene is built until after its threads are joined; the last lease to end finalizes TBB's
// scheduler, which joins TBB's worker threads when no other code in the process still uses TBB
// (another task_arena, or a thread that ran TBB work and is still alive). So a host that
// unloads libdpc after destroying its last engine (an LV2 host closing a session) has no TBB
// worker left running code that is about to be unmapped. Docs: docs/design.md "Thread roles".
#pragma once

namespace dpc::api {

class SchedulerLease {
 public:
  /// Control thread (any thread but the audio thread). May block briefly on the lease lock
  /// while the last lease of an earlier generation finalizes; allocates (TBB's handle).
  SchedulerLease();
  /// Control thread. The last lease finalizes TBB's scheduler: it waits until TBB's workers
  /// have left (they are idle: every engine's propagation thread is joined by then). If TBB is
  /// still in use elsewhere, nothing is waited for and the workers stay (TBB keeps them).
  ~SchedulerLease();
  SchedulerLease(const SchedulerLease&) = delete;
  SchedulerLease& operator=(const SchedulerLease&) = delete;
};

}  // namespace dpc::api
