/* dpc C API: an interactive sound-propagation engine behind opaque handles (C99).
 *
 * One dpc_engine owns a scene, a propagation thread (ray tracing into the diffuse path cache,
 * impulse-response synthesis) and the convolvers that apply the newest impulse response to the
 * dry source signals (docs/design.md "Library boundary" and "Thread roles").
 *
 * Thread roles used below:
 *   control thread: any one thread at a time that creates, starts, stops and destroys the engine;
 *   any thread:     lock-free and wait-free, may be called concurrently with process();
 *   audio thread:   the host's real-time callback; never allocates, locks, logs or waits.
 * No function throws: C++ exceptions are caught inside and turned into a dpc_status. The text
 * of the last error on the calling thread is returned by dpc_last_error().
 * Units: metres, seconds, degrees for the API's angles, linear sample values. */
#ifndef DPC_DPC_H
#define DPC_DPC_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#if defined(__GNUC__)
#define DPC_API __attribute__((visibility("default")))
#else
#define DPC_API
#endif

/** Result of every function that can fail. */
typedef enum dpc_status {
  DPC_OK = 0,
  DPC_ERR_INVALID_ARGUMENT = 1, /**< null handle/pointer or value out of range */
  DPC_ERR_INPUT = 2,            /**< scene file or one of its fields is invalid */
  DPC_ERR_STATE = 3,            /**< wrong engine state (e.g. started twice is fine; see fn) */
  DPC_ERR_UNSUPPORTED = 4,      /**< the operation is not available in this version */
  DPC_ERR_INTERNAL = 5          /**< unexpected failure (out of memory, runtime error) */
} dpc_status;

/** Opaque engine handle. */
typedef struct dpc_engine dpc_engine;

/** Any thread. The text of the last error raised on the calling thread ("" if none). The
 *  pointer stays valid until the next failing call on this thread. Never allocates after the
 *  first error on a thread. */
DPC_API const char* dpc_last_error(void);

/** Library version "MAJOR.MINOR.PATCH". Any thread; static storage. */
DPC_API const char* dpc_version(void);

/** Control thread. Loads a scene file (JSON, docs/scene-format.md), its meshes and dry
 *  signals, and builds the engine (Embree scene, IR synthesisers, convolvers). Allocates.
 *  On success *out receives a handle to free with dpc_engine_destroy; on failure *out is NULL
 *  and dpc_last_error() names the file and field. Errors: DPC_ERR_INVALID_ARGUMENT,
 *  DPC_ERR_INPUT, DPC_ERR_INTERNAL. */
DPC_API dpc_status dpc_engine_create_from_file(const char* scene_path, dpc_engine** out);

/** Control thread. Stops the threads if running and frees everything. NULL is ignored. The
 *  host must have stopped calling dpc_engine_process before. */
DPC_API void dpc_engine_destroy(dpc_engine* engine);

/** Control thread. Starts the propagation thread (idempotent). Allocates (thread creation). */
DPC_API dpc_status dpc_engine_start(dpc_engine* engine);
/** Control thread. Stops and joins the propagation thread (idempotent). */
DPC_API dpc_status dpc_engine_stop(dpc_engine* engine);

/** Any thread, wait-free, no allocation. Sets the listener pose: position (x, y, z) in metres
 *  in scene coordinates, yaw in degrees (0 faces +x, positive turns left, about +y), pitch in
 *  degrees (positive looks up). The propagation thread uses the newest pose at its next frame.
 *  Errors: DPC_ERR_INVALID_ARGUMENT (null engine or non-finite value). */
DPC_API dpc_status dpc_engine_set_listener(dpc_engine* engine, float x, float y, float z,
                                           float yaw_degrees, float pitch_degrees);

/** Any thread, wait-free, no allocation. Moves source `source` (0-based, scene order) to
 *  (x, y, z) metres in scene coordinates from the next propagation frame on, instead of its
 *  trajectory. Errors: DPC_ERR_INVALID_ARGUMENT (null engine, index out of range, non-finite
 *  value; no message is set, since setting one would allocate). */
DPC_API dpc_status dpc_engine_set_source_position(dpc_engine* engine, int source, float x,
                                                  float y, float z);

/** Any thread (one writer per object at a time), wait-free, no allocation. Places moving
 *  object `object` (0-based, the scene's "objects" order): world = R(q) * local + (x, y, z),
 *  metres; q = (qx, qy, qz, qw) a rotation quaternion in glTF order, normalised here. Replaces
 *  the object's trajectory from the next propagation frame on. Errors: DPC_ERR_INVALID_ARGUMENT
 *  (null engine, index out of range, non-finite value or zero quaternion; no message set). */
DPC_API dpc_status dpc_engine_set_object_pose(dpc_engine* engine, int object, float x, float y,
                                              float z, float qx, float qy, float qz, float qw);

/** Audio thread. Renders `frames` frames (1..8192, may vary from call to call) into
 *  outputs[0..dpc_engine_output_channels()), each a buffer of `frames` samples.
 *  inputs: NULL to play the scene's own dry signals, or one mono buffer of `frames` samples per
 *  source (scene order) holding the host's dry signal. The engine convolves in fixed blocks of
 *  dpc_engine_block_size() frames; a FIFO between the host's calls and those blocks adds a
 *  constant latency of dpc_engine_latency_frames() frames whatever the call pattern. Never
 *  allocates, locks, logs or waits. Errors: DPC_ERR_INVALID_ARGUMENT (null engine or outputs;
 *  frames outside 1..8192: nothing rendered, counted in dpc_stats.rejected_callbacks). */
DPC_API dpc_status dpc_engine_process(dpc_engine* engine, const float* const* inputs,
                                      float* const* outputs, int frames);

/** Any thread. Fixed properties of the engine (from the scene file). */
DPC_API int dpc_engine_sample_rate(const dpc_engine* engine);     /**< Hz */
DPC_API int dpc_engine_block_size(const dpc_engine* engine);      /**< engine block, frames */
DPC_API int dpc_engine_output_channels(const dpc_engine* engine); /**< 1 mono, 2 stereo */
DPC_API int dpc_engine_source_count(const dpc_engine* engine);
DPC_API int dpc_engine_object_count(const dpc_engine* engine);    /**< moving objects */
/** Latency process() adds to the host's signal, frames (one engine block). */
DPC_API int dpc_engine_latency_frames(const dpc_engine* engine);

/** Counters and last-frame measurements of a running engine. */
typedef struct dpc_stats {
  uint64_t frames;            /**< propagation frames run */
  double frame_ms;            /**< duration of the last propagation frame, ms */
  double rays_per_second;     /**< since the previous dpc_engine_get_stats call */
  uint64_t cache_entries;     /**< diffuse path cache entries after the last frame */
  uint64_t cache_bytes;       /**< heap bytes held by the caches, summed over sources */
  uint64_t cache_budget_bytes; /**< their memory budget, summed over sources */
  uint64_t cache_merged_entries; /**< path entries merged into coarse delay bins, cumulative */
  double cache_merged_energy_fraction; /**< largest per-source share of the response's energy
                                            read from merged entries, [0, 1] */
  uint64_t irs_applied;       /**< impulse-response sets that reached the convolvers */
  uint64_t irs_dropped;       /**< superseded before the audio thread applied them */
  double ir_age_ms;           /**< age of the impulse response playing, ms */
  uint64_t blocks;            /**< engine blocks rendered */
  uint64_t nan_blocks;        /**< blocks zeroed because they held NaN or infinity */
  uint64_t late_callbacks;    /**< process() calls that took longer than the audio they
                                   produced (a device would have underrun) */
  uint64_t rejected_callbacks; /**< process() calls with frames outside 1..8192 */
} dpc_stats;

/** Control thread (it updates the rays-per-second interval). No allocation. */
DPC_API dpc_status dpc_engine_get_stats(dpc_engine* engine, dpc_stats* out);

#ifdef __cplusplus
}
#endif
#endif /* DPC_DPC_H */
