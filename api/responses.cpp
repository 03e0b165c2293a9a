// Audio and read-outs across the C API: dpc_engine_process on the host's audio thread, the
// newest impulse and energy responses, fixed properties and statistics (include/dpc/dpc.h).
#include <algorithm>
#include <cstring>

#include "api/engine_handle.h"
#include "api/errors.h"
#include "api/layouts.h"
#include "runtime/session_stats.h"

using dpc::api::checkIndex;
using dpc::api::EngineCall;
using dpc::api::engineProperty;
using dpc::api::fail;
using dpc::api::failFixed;
using dpc::api::guarded;

namespace {

/// The arguments every read-out shares, once `call` has entered the engine: DPC_OK, or the
/// status with a message naming the one that is wrong (a NULL engine or one being destroyed,
/// a source out of range, out NULL with room).
dpc_status checkReadout(const char* function, const EngineCall& call, const dpc_engine* engine,
                        int source, const float* out, size_t capacity) {
  if (const dpc_status s = call.check(function); s != DPC_OK) return s;
  if (const dpc_status s = checkIndex(function, "source", source, engine->sources, "sources");
      s != DPC_OK)
    return s;
  if (!out && capacity > 0)
    return failFixed(DPC_ERR_INVALID_ARGUMENT, function, "out is NULL with a capacity > 0");
  return DPC_OK;
}

static_assert(DPC_MAX_ORDER_WARN_FRACTION == dpc::kMaxOrderWarnFraction,
              "dpc.h's max_order bound mirrors runtime/session_stats.h's");

/// dpc_stats at the current layout from the session's status.
dpc_stats statsOf(const dpc::SessionStatus& s) {
  dpc_stats out{};
  out.struct_size = sizeof out;
  out.frames = s.frames;
  out.frame_ms = s.frameMs;
  out.rays_per_second = s.raysPerSecond;
  out.cache_entries = s.cacheEntries;
  out.irs_applied = s.irsApplied;
  out.irs_dropped = s.irsDropped;
  out.ir_age_ms = s.irAgeMs;
  out.blocks = s.blocks;
  out.nan_blocks = s.nanBlocks;
  out.late_callbacks = s.lateCallbacks;
  out.rejected_callbacks = s.rejectedCallbacks;
  out.cache_bytes = s.cacheBytes;
  out.cache_budget_bytes = s.cacheBudgetBytes;
  out.cache_merged_entries = s.cacheMergedEntries;
  out.cache_merged_energy_fraction = s.cacheMergedEnergyFraction;
  out.rays_per_frame = int32_t(s.raysPerFrame);
  out.rays_per_frame_min = int32_t(s.raysPerFrameMin);
  out.reduced_frames = s.reducedFrames;
  out.baked_responses = s.bakedResponses;
  out.bake_fallbacks = s.bakeFallbacks;
  out.input_samples_replaced = s.inputSamplesReplaced;
  out.limited_frames = s.limitedFrames;
  out.dropped_energy_fraction = s.droppedEnergyFraction;
  out.max_order_energy_fraction = s.maxOrderEnergyFraction;
  return out;
}

}  // namespace

extern "C" {

dpc_status dpc_engine_copy_impulse_response(dpc_engine* engine, int source, int channel, float* out,
                                            size_t capacity, size_t* length, uint64_t* frame) {
  constexpr const char* kFunction = "dpc_engine_copy_impulse_response";
  const EngineCall call(engine);
  if (const dpc_status s = checkReadout(kFunction, call, engine, source, out, capacity);
      s != DPC_OK)
    return s;
  if (const dpc_status s =
          checkIndex(kFunction, "channel", channel, engine->session->irChannels(), "channels");
      s != DPC_OK)
    return s;
  const bool ok = engine->session->copyResponses(size_t(source), [&](const auto& r) {
    const std::span<const float> ir = r.ir->channelSpan(channel);
    if (length) *length = ir.size();
    if (frame) *frame = r.frame;
    if (out && capacity > 0)
      std::memcpy(out, ir.data(), std::min(capacity, ir.size()) * sizeof(float));
  });
  return ok ? DPC_OK
            : fail(DPC_ERR_STATE, "dpc_engine_copy_impulse_response: no propagation frame yet");
}

dpc_status dpc_engine_copy_energy_response(dpc_engine* engine, int source, float* out,
                                           size_t capacity_bins, size_t* bins, double* bin_seconds,
                                           uint64_t* frame) {
  const EngineCall call(engine);
  if (const dpc_status s = checkReadout("dpc_engine_copy_energy_response", call, engine, source,
                                        out, capacity_bins);
      s != DPC_OK)
    return s;
  static_assert(DPC_BANDS == dpc::kNumBands, "band count of the public API");
  const bool ok = engine->session->copyResponses(size_t(source), [&](const auto& r) {
    if (bins) *bins = r.energy->size();
    if (bin_seconds) *bin_seconds = r.binSeconds;
    if (frame) *frame = r.frame;
    const size_t n = std::min(capacity_bins, r.energy->size());
    for (size_t k = 0; k < n; ++k)
      for (int b = 0; b < DPC_BANDS; ++b) out[k * DPC_BANDS + size_t(b)] = (*r.energy)[k][b];
  });
  return ok ? DPC_OK
            : fail(DPC_ERR_STATE, "dpc_engine_copy_energy_response: no propagation frame yet");
}

dpc_status dpc_engine_process(dpc_engine* engine, const float* const* inputs, float* const* outputs,
                              int frames) {
  const EngineCall call(engine);
  if (call.status() != DPC_OK) return call.status();
  if (!outputs) return DPC_ERR_INVALID_ARGUMENT;
  for (int c = 0; c < engine->session->outputChannels(); ++c)
    if (!outputs[c]) return DPC_ERR_INVALID_ARGUMENT;
  if (inputs)
    for (int s = 0; s < engine->sources; ++s)
      if (!inputs[s]) return DPC_ERR_INVALID_ARGUMENT;
  // The session adapts any callback size to its block; sizes outside 1..8192 output nothing and
  // are counted (dpc_stats.rejected_callbacks).
  engine->session->render(inputs, outputs, frames);
  return frames >= 1 && frames <= dpc::LiveSession::kMaxCallbackFrames ? DPC_OK
                                                                       : DPC_ERR_INVALID_ARGUMENT;
}

int dpc_engine_sample_rate(const dpc_engine* e) {
  return engineProperty(e, [](const dpc_engine& x) { return x.session->sampleRate(); });
}
int dpc_engine_block_size(const dpc_engine* e) {
  return engineProperty(e, [](const dpc_engine& x) { return x.session->blockSize(); });
}
int dpc_engine_output_channels(const dpc_engine* e) {
  return engineProperty(e, [](const dpc_engine& x) { return x.session->outputChannels(); });
}
int dpc_engine_ir_channels(const dpc_engine* e) {
  return engineProperty(e, [](const dpc_engine& x) { return x.session->irChannels(); });
}
int dpc_engine_source_count(const dpc_engine* e) {
  return engineProperty(e, [](const dpc_engine& x) { return x.sources; });
}
int dpc_engine_object_count(const dpc_engine* e) {
  return engineProperty(e, [](const dpc_engine& x) { return x.session->objectCount(); });
}
int dpc_engine_latency_frames(const dpc_engine* e) {
  return engineProperty(e, [](const dpc_engine& x) { return x.session->adapterLatencyFrames(); });
}

dpc_status dpc_engine_get_stats(dpc_engine* engine, dpc_stats* out) {
  constexpr const char* kFunction = "dpc_engine_get_stats";
  const EngineCall call(engine);
  if (const dpc_status s = call.check(kFunction); s != DPC_OK) return s;
  if (!out) return failFixed(DPC_ERR_INVALID_ARGUMENT, kFunction, "out is NULL");
  using Stats = dpc::api::Layouts<dpc_stats>;
  if (const dpc_status s = dpc::api::checkLayout(Stats::kName, Stats::kKnown, out->struct_size);
      s != DPC_OK)
    return s;  // before status(), which restarts the rays-per-second interval
  return guarded([&] {
    return dpc::api::writeVersioned(out, out->struct_size, statsOf(engine->session->status()));
  });
}

}  // extern "C"
