// The object behind the C API's opaque dpc_engine handle: the scene, the dry signals and the
// LiveSession that plays them (docs/design.md "Library boundary"), and the count of calls
// inside it that dpc_engine_destroy waits for (dpc.h, "Lifetime").
#pragma once

#include <atomic>
#include <memory>
#include <optional>

#include "api/scheduler_lease.h"
#include "dpc/dpc.h"
#include "runtime/live_session.h"
#include "runtime/render_pipeline.h"
#include "scene/scene.h"

struct dpc_engine {
  /// First member: taken before the scene is built, given back by destroyEngine after the
  /// session's threads are joined (api/scheduler_lease.h), not when the closed handle is freed
  /// (that is up to 64 destroys later).
  std::optional<dpc::api::SchedulerLease> lease{std::in_place};
  dpc::SceneDesc scene;  ///< built by create, then moved into the session, which shares it
  dpc::DrySignals dry;   ///< likewise
  std::unique_ptr<dpc::LiveSession> session;
  int sources = 0;
  mutable std::atomic<int> calls{0};  ///< entry points using the engine now (EngineCall)
  std::atomic<bool> closing{false};   ///< dpc_engine_destroy has begun: calls are refused
};

namespace dpc::api {

/// Control thread: moves the engine's complete scene and dry signals into the session that
/// shares them (every listener stands where the scene puts it at time 0 until the host sets a
/// pose) and logs the scene's warnings. Allocates;
/// throws what LiveSession throws. Returns the released handle.
dpc_engine* finishEngine(std::unique_ptr<dpc_engine> engine);

/// One entry point's use of an engine (dpc.h "Lifetime"): counted in for the object's scope,
/// so that dpc_engine_destroy waits for it, unless the engine is NULL or being destroyed. Any
/// thread, the audio thread too: wait-free (two atomic operations), no allocation.
class EngineCall {
 public:
  explicit EngineCall(const dpc_engine* engine) noexcept;
  ~EngineCall();
  EngineCall(const EngineCall&) = delete;
  EngineCall& operator=(const EngineCall&) = delete;

  /// DPC_OK when the call may use the engine; DPC_ERR_INVALID_ARGUMENT for a NULL engine,
  /// DPC_ERR_STATE for one being destroyed. Sets no message (the audio thread's form).
  dpc_status status() const noexcept { return status_; }
  /// As status(), with "FUNCTION: engine is NULL" or "FUNCTION: the engine is being
  /// destroyed" as the thread's message (failFixed: no allocation).
  dpc_status check(const char* function) const noexcept;

 private:
  const dpc_engine* counted_;  ///< the engine counted in, or nullptr
  dpc_status status_;
};

/// The value of an int property `read(engine)`, or 0 for a NULL engine or one being
/// destroyed. Any thread; no allocation.
template <class Read>
int engineProperty(const dpc_engine* engine, Read read) {
  const EngineCall call(engine);
  return call.status() == DPC_OK ? read(*engine) : 0;
}

/// Control thread: dpc_engine_destroy (dpc.h "Lifetime"). Closes the engine (calls are refused
/// from now on), waits for the calls inside it to return and logs a warning with their count
/// if there were any, stops and frees the session, gives back its TBB lease, then keeps the closed handle among the last
/// 64 destroyed (freeing the oldest), so that a late call is refused rather than reading freed
/// memory. Never throws.
void destroyEngine(dpc_engine* engine) noexcept;

}  // namespace dpc::api
