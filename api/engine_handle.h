// The object behind the C API's opaque dpc_engine handle: the scene, the dry signals and the
// LiveSession that plays them (docs/design.md "Library boundary").
#pragma once

#include <memory>

#include "api/scheduler_lease.h"
#include "dpc/dpc.h"
#include "runtime/live_session.h"
#include "runtime/render_pipeline.h"
#include "scene/scene.h"

struct dpc_engine {
  /// First member: taken before the scene is built, given back after the session's threads
  /// are joined (api/scheduler_lease.h).
  dpc::api::SchedulerLease lease;
  dpc::SceneDesc scene;  ///< built by create, then moved into the session, which shares it
  dpc::DrySignals dry;   ///< likewise
  std::unique_ptr<dpc::LiveSession> session;
  int sources = 0;
};

namespace dpc::api {

/// Control thread: moves the engine's complete scene and dry signals into the session that
/// shares them (every listener stands where the scene puts it at time 0 until the host sets a
/// pose) and logs the scene's warnings. Allocates;
/// throws what LiveSession throws. Returns the released handle.
dpc_engine* finishEngine(std::unique_ptr<dpc_engine> engine);

}  // namespace dpc::api
