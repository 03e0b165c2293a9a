// Baked playback across the C API (include/dpc/dpc.h): opening a bake against an engine's
// scene (bake/bake_loader.h) and attaching it to the engine's session.
#include <cstdint>
#include <memory>

#include "api/engine_handle.h"
#include "api/errors.h"
#include "engine/baked_field.h"
#ifdef DPC_HAVE_BAKE
#include "bake/bake_loader.h"
#include "bake/settings_hash.h"
#endif

/// The object behind the opaque dpc_bake handle: the bake, shared with the engines it is
/// attached to, and the playback settings hash of the scene it was checked against
/// (bake/settings_hash.h).
struct dpc_bake {
  std::shared_ptr<const dpc::BakedField> field;
#ifdef DPC_HAVE_BAKE
  dpc::bake::SettingsHash sceneHash{};
#endif
};

using dpc::api::fail;
using dpc::api::guarded;

extern "C" {

dpc_status dpc_bake_open(const dpc_engine* engine, const char* bake_path, dpc_bake** out) {
  if (!out) return fail(DPC_ERR_INVALID_ARGUMENT, "dpc_bake_open: out is NULL");
  *out = nullptr;
  const dpc::api::EngineCall call(engine);
  if (const dpc_status s = call.check("dpc_bake_open"); s != DPC_OK) return s;
  if (!bake_path) return fail(DPC_ERR_INVALID_ARGUMENT, "dpc_bake_open: bake_path is NULL");
#ifdef DPC_HAVE_BAKE
  return guarded([&] {
    auto bake = std::make_unique<dpc_bake>();
    const dpc::SceneDesc& scene = engine->session->scene();
    bake->field = dpc::bake::loadBakedField(bake_path, scene);
    bake->sceneHash = dpc::bake::playbackHash(scene);
    *out = bake.release();
    return DPC_OK;
  });
#else
  return fail(DPC_ERR_UNSUPPORTED, "dpc_bake_open: this library was built without HDF5");
#endif
}

int dpc_bake_probe_count(const dpc_bake* bake) {
  return bake ? int(bake->field->probes.size()) : -1;
}

void dpc_bake_destroy(dpc_bake* bake) { delete bake; }

dpc_status dpc_engine_attach_bake(dpc_engine* engine, const dpc_bake* bake) {
  const dpc::api::EngineCall call(engine);
  if (const dpc_status s = call.check("dpc_engine_attach_bake"); s != DPC_OK) return s;
  return guarded([&] {
#ifdef DPC_HAVE_BAKE
    if (bake && dpc::bake::firstDifference(bake->sceneHash,
                                           dpc::bake::playbackHash(engine->session->scene()),
                                           true) >= 0)
      return fail(DPC_ERR_INVALID_ARGUMENT,
                  "dpc_engine_attach_bake: the bake is of another scene than the engine's");
#endif
    return engine->session->attachBake(bake ? bake->field : nullptr)
               ? DPC_OK
               : fail(DPC_ERR_STATE, "dpc_engine_attach_bake: the engine is running");
  });
}

}  // extern "C"
