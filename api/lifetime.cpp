// The C API's lifetime rule (include/dpc/dpc.h, "Lifetime"): every entry point counts itself
// into the engine it uses; dpc_engine_destroy closes the engine, waits for those calls and
// keeps the closed handle a while instead of freeing it at once.
#include <array>
#include <chrono>
#include <mutex>
#include <string>
#include <thread>

#include "api/engine_handle.h"
#include "api/errors.h"
#include "common/log.h"

namespace dpc::api {
namespace {

constexpr size_t kClosedHandlesKept = 64;

/// The handles of the last kClosedHandlesKept engines destroyed: closed (every call refused),
/// their sessions already freed. A new one replaces the oldest, which is freed.
struct ClosedHandles {
  std::mutex mutex;
  std::array<std::unique_ptr<dpc_engine>, kClosedHandlesKept> kept;
  size_t next = 0;
};

ClosedHandles& closedHandles() {
  static ClosedHandles handles;
  return handles;
}

void keepClosed(dpc_engine* engine) noexcept {
  std::unique_ptr<dpc_engine> oldest(engine);
  ClosedHandles& h = closedHandles();
  const std::lock_guard lock(h.mutex);
  std::swap(oldest, h.kept[h.next]);
  h.next = (h.next + 1) % kClosedHandlesKept;
}  // the oldest handle is freed here

}  // namespace

// The counter and the flag are sequentially consistent on both sides: either a call's
// increment comes before destroy's read of the count (destroy waits for it), or the call sees
// the flag (and backs out).
EngineCall::EngineCall(const dpc_engine* engine) noexcept : counted_(engine), status_(DPC_OK) {
  if (!engine) {
    status_ = DPC_ERR_INVALID_ARGUMENT;
    return;
  }
  engine->calls.fetch_add(1);
  if (engine->closing.load()) {
    engine->calls.fetch_sub(1);
    counted_ = nullptr;
    status_ = DPC_ERR_STATE;
  }
}

EngineCall::~EngineCall() {
  if (counted_) counted_->calls.fetch_sub(1, std::memory_order_release);
}

dpc_status EngineCall::check(const char* function) const noexcept {
  if (status_ == DPC_ERR_INVALID_ARGUMENT) return failFixed(status_, function, "engine is NULL");
  if (status_ == DPC_ERR_STATE)
    return failFixed(status_, function, "the engine is being destroyed");
  return status_;
}

void destroyEngine(dpc_engine* engine) noexcept {
  engine->closing.store(true);
  const int inside = engine->calls.load();
  while (engine->calls.load(std::memory_order_acquire) != 0)
    std::this_thread::sleep_for(std::chrono::microseconds(100));
  try {
    if (inside > 0)
      logMessage(LogLevel::kWarning,
                 "dpc_engine_destroy: " + std::to_string(inside) +
                     " call(s) on other threads were still inside the engine; waited for them "
                     "(no call may overlap dpc_engine_destroy: dpc.h, \"Lifetime\")");
    engine->session->stop();
  } catch (...) {
  }
  engine->session.reset();
  engine->lease.reset();  // the last engine's lease joins TBB's workers now
  keepClosed(engine);
}

}  // namespace dpc::api
