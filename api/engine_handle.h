// The object behind the C API's opaque dpc_engine handle: the scene, the dry signals and the
// LiveSession that plays them (docs/design.md "Library boundary").
#pragma once

#include <memory>

#include "dpc/dpc.h"
#include "runtime/live_session.h"
#include "runtime/render_pipeline.h"
#include "scene/scene.h"

struct dpc_engine {
  dpc::SceneDesc scene;
  dpc::DrySignals dry;
  std::unique_ptr<dpc::LiveSession> session;
  int sources = 0;
};

namespace dpc::api {

/// Control thread: builds the session over the engine's complete scene and dry signals, places
/// the listener where the scene puts it at time 0 and logs the scene's warnings. Allocates;
/// throws what LiveSession throws. Returns the released handle.
dpc_engine* finishEngine(std::unique_ptr<dpc_engine> engine);

}  // namespace dpc::api
