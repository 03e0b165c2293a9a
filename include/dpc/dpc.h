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
 * of the last error on the calling thread is returned by dpc_last_error(); warnings go to the
 * log callback (dpc_set_log_callback).
 * Units: metres, seconds, degrees for the API's angles, linear sample values.
 *
 * Poses (listeners, sources, moving objects; the one frame for every pose): dpc/dpc_poses.h,
 * included at the end of this header.
 *
 * Lifetime: create, start, stop, step, get_stats, attach_bake and destroy are control-thread
 * calls, one at a time per engine. The any-thread calls (poses, selection, teleports, copies,
 * properties) may overlap each other and any control-thread call but destroy, from any number
 * of threads; dpc_engine_process runs on one audio thread at a time. dpc_engine_destroy must
 * not overlap any other call on the same engine: stop the audio callback and the other
 * threads' calls first; no call may use the handle after destroy. A host that breaks this is
 * caught where the library can: destroy first closes the engine (a call arriving from then on
 * does nothing and returns DPC_ERR_STATE, "the engine is being destroyed", or a property
 * 0), waits for the calls
 * already inside it to return, logs a warning with their count, and only then frees the
 * engine; the handles of the last 64 engines destroyed stay closed rather than freed, so that
 * a late call from such a thread is refused instead of reading freed memory.
 *
 * Versions and growth rule. DPC_VERSION (dpc_version.h, this header's) and dpc_version() (the
 * library's): a program compiled against the dpc.h of release R runs with the library of any
 * release of R's major version not older than R, for R from 0.5.0 on
 * (DPC_VERSION_COMPATIBLE(dpc_version())), because:
 *  1. Functions are never removed and keep their signature and meaning; new behaviour comes as
 *     new functions or new struct fields.
 *  2. A versioned struct (first member struct_size: dpc_engine_options, dpc_scene_data,
 *     dpc_stats) grows only at its end, by a group of fields that starts at the previous
 *     release's size (the library checks that no new field lands in old tail padding). The
 *     structs dpc_scene_data points to never change; a new per-element field comes as a new
 *     parallel array in dpc_scene_data (as source_directivities).
 *  3. struct_size names the layout. The library knows every layout of each versioned struct
 *     since 0.5.0 (one table per struct). A known size is served: an input struct (options,
 *     scene data) is read up to its struct_size, the fields it lacks take the defaults of its
 *     _init function; an output struct (dpc_stats) is written up to its struct_size only. Any
 *     other size (zero, larger than the library's, between two layouts) gives DPC_ERR_VERSION,
 *     nothing read or written, and dpc_last_error() names the size given and the sizes known.
 *  4. The _init functions fill the caller's layout: dpc_engine_options_init(o) and
 *     dpc_scene_data_init(d) are macros passing this header's sizeof to the _init_sized
 *     functions; the plain functions of those names, which programs compiled against 0.6.0 and
 *     earlier call, fill the 0.6.0 layout.
 *  5. The soname (libdpc.so.MAJOR) stays within a major version.
 * Releases before 0.5.0 are not served: 0.4.0's dpc_scene_data has 0.5.0's size but another
 * layout (listener_roll_degrees was inserted, dpc_listener grew). */
#ifndef DPC_DPC_H
#define DPC_DPC_H

#include <stddef.h>
#include <stdint.h>

#include "dpc/dpc_version.h"

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
  DPC_ERR_STATE = 3,            /**< not possible in the engine's current state (e.g.
                                     dpc_engine_step while running, a read before any frame) */
  DPC_ERR_UNSUPPORTED = 4,      /**< the operation is not available in this version */
  DPC_ERR_INTERNAL = 5,         /**< unexpected failure (out of memory, runtime error) */
  DPC_ERR_VERSION = 6           /**< a struct's struct_size is not a layout this library knows
                                     (the growth rule at the top of this header) */
} dpc_status;

/** Opaque engine handle. */
typedef struct dpc_engine dpc_engine;

/** Any thread. The text of the last error raised on the calling thread ("" if none). The
 *  pointer stays valid until the next failing call on this thread. Reading it never
 *  allocates. The "any thread" functions that can fail write their message into a fixed
 *  per-thread buffer (no allocation; cut at 255 bytes); dpc_engine_process, the audio
 *  thread's, sets none (its status code says it all). */
DPC_API const char* dpc_last_error(void);

/** Any thread; no allocation. The library's version, packed as DPC_MAKE_VERSION(major, minor,
 *  patch) (dpc_version.h): DPC_VERSION_COMPATIBLE(dpc_version()) is true when the library
 *  serves a program compiled against this header (same major, not older). */
DPC_API unsigned long dpc_version(void);

/** Severity of a log message. */
typedef enum dpc_log_level {
  DPC_LOG_INFO = 0,
  DPC_LOG_WARNING = 1, /**< e.g. a scene file's degenerate triangles, skipped */
  DPC_LOG_ERROR = 2
} dpc_log_level;

/** Receives one log message: a single line without a trailing newline, valid only during the
 *  call. */
typedef void (*dpc_log_callback)(dpc_log_level level, const char* message, void* user_data);

/** Any thread but the audio thread; no allocation. Sends the library's warnings and messages to
 *  `callback` (with `user_data`) for the whole process, replacing the previous one; NULL
 *  restores the default, which prints them to stderr ("warning: " before a warning). The
 *  callback runs on the thread whose dpc call raises the message (the control thread creating
 *  an engine; never the audio thread), one call at a time (the library serialises them under a
 *  lock, so it must not call dpc_set_log_callback itself). When this function returns, the
 *  previous callback is not running and will not be called again (its user_data may be
 *  freed); it waits for a call in progress. Errors of a call are not logged: they are its
 *  dpc_status and dpc_last_error(). */
DPC_API void dpc_set_log_callback(dpc_log_callback callback, void* user_data);

/** Output format of an engine (docs/spatial.md): 1 channel, 2 channels by constant-power
 *  panning of each arrival direction, 2 ear channels through HRTFs, AmbiX ((order + 1)^2
 *  channels, ACN order, SN3D normalisation; since 0.4.0), or 2 ear channels decoded from AmbiX
 *  impulse responses turned by the listener's head orientation on every audio block (head
 *  tracking without waiting for a propagation frame; since 0.4.0). */
typedef enum dpc_output_format {
  DPC_OUTPUT_SCENE = 0, /**< as the scene says (dpc_engine_options only) */
  DPC_OUTPUT_MONO = 1,
  DPC_OUTPUT_STEREO = 2,
  DPC_OUTPUT_BINAURAL = 3,
  DPC_OUTPUT_AMBISONICS = 4,
  DPC_OUTPUT_AMBISONIC_BINAURAL = 5
} dpc_output_format;

/** How the sources' impulse responses are rendered (docs/design.md, "Audio side"): each whole,
 *  or hybrid (each source's early part on its own, the late part once per cluster of sources
 *  through a shared late bus: Schissler & Manocha, ACM TOG 2016). AUTO is hybrid when the
 *  sources outnumber the late buses. Since 0.4.0. */
typedef enum dpc_rendering {
  DPC_RENDERING_AUTO = 0,
  DPC_RENDERING_PER_SOURCE = 1,
  DPC_RENDERING_HYBRID = 2
} dpc_rendering;

/** How traced paths become the energy response (docs/estimators.md): the diffuse path cache
 *  (Schissler's thesis, section 3.2.2), or plain Monte Carlo path tracing with no reuse
 *  between frames (what the DPC is at cache_tau 0). Since 0.8.0. */
typedef enum dpc_estimator {
  DPC_ESTIMATOR_DPC = 0,
  DPC_ESTIMATOR_PATH_TRACING = 1
} dpc_estimator;

/** Which end the rays leave from (docs/performance.md, "Many sources"): one trace per source
 *  tested against every listener sphere, or one per listener tested against every source
 *  sphere (reciprocal: the same energy response in expectation). AUTO traces from the
 *  listeners when the sources outnumber them. Since 0.8.0. */
typedef enum dpc_tracing {
  DPC_TRACING_AUTO = 0,
  DPC_TRACING_FROM_SOURCES = 1,
  DPC_TRACING_FROM_LISTENERS = 2
} dpc_tracing;

/** Overrides of a scene's settings when an engine is created. Fill with
 *  dpc_engine_options_init() (struct_size set, every other field "keep the scene's"), then
 *  change what you need. */
typedef struct dpc_engine_options {
  size_t struct_size;       /**< its layout's size, set by dpc_engine_options_init */
  int sample_rate;          /**< Hz, 16000..192000; 0 keeps the scene's audio.sample_rate. Dry
                                 signals are resampled to it, HRTFs read at it. */
  int block_size;           /**< engine block, frames, 16..8192; 0 keeps the scene's */
  int rays_per_frame;       /**< rays per source per frame, 1..10^8; 0 keeps the scene's */
  dpc_output_format output; /**< DPC_OUTPUT_SCENE keeps the scene's audio.output */
  int host_inputs_only;     /**< nonzero: the scene's dry signals are not read (sources may have
                                 none); dpc_engine_process then needs inputs, and plays silence
                                 for inputs == NULL */
  int ambisonic_order;      /**< AmbiX outputs' order, 1..7; 0 keeps the scene's (since 0.4.0) */
  /* Since 0.7.0. */
  float ir_length; /**< impulse response length, s, (0, 60]; 0 keeps the scene's */
} dpc_engine_options;

/** Any thread; no allocation. Fills the first struct_size bytes of *options, a layout this
 *  library knows (the growth rule): struct_size, and every other field "keep the scene's"
 *  (zero). Errors: DPC_ERR_INVALID_ARGUMENT (NULL), DPC_ERR_VERSION (an unknown size: nothing
 *  written). Since 0.7.0; call it through the dpc_engine_options_init macro. */
DPC_API dpc_status dpc_engine_options_init_sized(dpc_engine_options* options, size_t struct_size);
/** The 0.6.0 entry point, for programs compiled against 0.6.0 and earlier: fills the 0.6.0
 *  layout. NULL is ignored. */
DPC_API void(dpc_engine_options_init)(dpc_engine_options* options);
/** Fills *options for this header's layout (dpc_engine_options_init_sized). */
#define dpc_engine_options_init(options) \
  dpc_engine_options_init_sized((options), sizeof(dpc_engine_options))

/** Control thread. Loads a scene file (JSON, docs/scene-format.md), its meshes and dry
 *  signals (unless options->host_inputs_only), applies the overrides in `options` (NULL: none)
 *  and builds the engine (Embree scene, IR synthesisers, convolvers). Allocates. The scene
 *  file's warnings go to the log callback. On success *out receives a handle to free with
 *  dpc_engine_destroy; on failure *out is NULL and dpc_last_error() names the file and field.
 *  Errors: DPC_ERR_INVALID_ARGUMENT (NULL path or out, an option out of range: the message
 *  names the field), DPC_ERR_VERSION (options->struct_size), DPC_ERR_INPUT, DPC_ERR_INTERNAL. */
DPC_API dpc_status dpc_engine_create_from_file(const char* scene_path,
                                               const dpc_engine_options* options,
                                               dpc_engine** out);

/** Number of octave bands of absorption and energy responses: 63, 125, 250, 500, 1000, 2000,
 *  4000 and 8000 Hz nominal centres (ISO 266, IEC 61260-1). */
#define DPC_BANDS 8

/** dpc_scene_data.cache_pool_mb for a path cache pool sized by the scene (since 0.7.0). */
#define DPC_CACHE_POOL_AUTO (-1.0f)

/** A surface material for dpc_scene_data. */
typedef struct dpc_material {
  const char* name;            /**< for error messages; may be NULL */
  float absorption[DPC_BANDS]; /**< energy absorption coefficient per octave band, [0, 1]
                                    (ISO 354 sense) */
  float scattering;            /**< scattering coefficient, [0, 1]: fraction of the reflected
                                    energy that leaves diffusely (Lambert) rather than
                                    specularly (ISO 17497-1); the same in every octave band
                                    here (a scene file may give one per band) */
} dpc_material;

/** A static triangle mesh, world coordinates in metres (y up by convention). */
typedef struct dpc_mesh {
  const float* vertices; /**< vertex_count * 3 floats: x, y, z of each vertex, m */
  uint32_t vertex_count;
  const uint32_t* indices;   /**< triangle_count * 3 vertex indices, < vertex_count */
  uint32_t triangle_count;   /**< > 0; degenerate triangles are dropped as from a file */
  const uint32_t* materials; /**< triangle_count indices into dpc_scene_data.materials */
} dpc_mesh;

/** A sound source for dpc_scene_data (an omnidirectional point source). */
typedef struct dpc_source {
  float position[3];   /**< m */
  float gain_db;       /**< dB applied to the dry signal, [-200, 200] */
  const float* signal; /**< mono dry signal at the engine's rate (the options'
                            sample_rate if set, else dpc_scene_data.sample_rate), copied at
                            creation; NULL (with signal_frames 0) for host inputs only */
  size_t signal_frames;
  int loop; /**< nonzero: repeat the signal */
} dpc_source;

/** A source's radiation pattern and orientation for dpc_scene_data (docs/scene-format.md,
 *  "sources[i].directivity"; scene/directivity.h). First-order: energy gain
 *  g = ((1 - a) + a cos theta)^2 at the angle theta from the forward axis (Eargle, "The
 *  Microphone Book", ch. 5), applied as g / <g> (<g> = (1 - a)^2 + a^2 / 3, its mean over the
 *  sphere) so the source's total power is unchanged and its on-axis intensity rises by the
 *  directivity factor 1 / <g>. An array parallel to dpc_scene_data.sources. */
typedef struct dpc_source_directivity {
  float a[8];        /**< per octave band 63 Hz .. 8 kHz, [0, 1]: 0 omni, 0.3 subcardioid,
                          0.5 cardioid, 0.63 supercardioid, 0.75 hypercardioid, 1 figure 8 */
  float rotation[4]; /**< orientation quaternion [x, y, z, w] (glTF order), normalised; the
                          forward axis is rotation * (+x); {0, 0, 0, 1}: facing +x; zero
                          length is an error */
} dpc_source_directivity;

/** A material's sound reduction index for dpc_scene_data (docs/scene-format.md,
 *  "materials.*.transmission_loss_db"): the surface passes tau = 10^(-R/10) of the incident
 *  energy to its other side, and tau <= absorption is required in every band (absorption counts
 *  the transmitted part). An array parallel to dpc_scene_data.materials. Since 0.7.0. */
typedef struct dpc_material_transmission {
  float loss_db[DPC_BANDS]; /**< R per octave band 63 Hz .. 8 kHz, dB, [0, 200], or INFINITY:
                                 opaque */
} dpc_material_transmission;

/** A further listener for dpc_scene_data (the first is given by its listener_* fields). */
typedef struct dpc_listener {
  float position[3];    /**< m */
  float radius;         /**< receiver sphere radius, m, (0, 1000000] */
  float yaw_degrees;    /**< [-3600, 3600]; 0 faces +x, positive turns left (about +y) */
  float pitch_degrees;  /**< [-90, 90]; positive looks up */
  float roll_degrees;   /**< [-180, 180]; about forward, positive: the right ear down */
} dpc_listener;

/** A scene built in code: what a scene file says (docs/scene-format.md), same defaults.
 *  Fill with dpc_scene_data_init(), then set mesh, materials and sources. The structs it
 *  points to (dpc_mesh, dpc_material, dpc_source, dpc_source_directivity, dpc_listener,
 *  dpc_material_transmission) never change (the growth rule). */
typedef struct dpc_scene_data {
  size_t struct_size; /**< its layout's size, set by dpc_scene_data_init */
  dpc_mesh mesh;
  const dpc_material* materials;
  int material_count; /**< >= 1 */
  const dpc_source* sources;
  int source_count;           /**< >= 1 */
  float listener_position[3]; /**< m */
  float listener_radius;      /**< receiver sphere radius, m, (0, 1000000] */
  float listener_yaw_degrees; /**< [-3600, 3600]; 0 faces +x, positive turns left (+y) */
  float listener_pitch_degrees; /**< [-90, 90]; positive looks up */
  float listener_roll_degrees;  /**< [-180, 180]; about forward, positive: the right ear down
                                     (since 0.5.0) */
  /* propagation (docs/estimators.md) */
  int rays_per_frame;   /**< rays per source per frame, [1, 100000000] */
  int max_order;        /**< maximum reflection order, [0, 10000] */
  float patch_size;     /**< DPC patch size lambda, m, > 0 */
  float cache_tau;      /**< DPC time window tau, s, [0, 3600] (0: no reuse) */
  float frame_rate;     /**< propagation frames per second, Hz, [1, 120] */
  float ir_length;      /**< impulse response length, s, (0, 60] */
  uint64_t seed;        /**< random seed: same seed, same bits */
  float speed_of_sound; /**< m/s, [1, 10000]; 0 (the default): dry air at `temperature`,
                             331.3 sqrt(1 + T / 273.15) m/s */
  float temperature;    /**< air temperature, degrees Celsius (ISO 9613-1), [-50, 60] */
  float humidity;       /**< relative humidity, percent, [0, 100] (ISO 9613-1) */
  int air_absorption;   /**< nonzero: ISO 9613-1 air absorption along paths */
  int diffraction;      /**< nonzero: first-order edge diffraction of the direct sound */
  /* audio */
  int sample_rate;          /**< Hz, [16000, 192000] */
  int block_size;           /**< engine block, frames, [16, 8192] */
  dpc_output_format output; /**< MONO, STEREO, BINAURAL (default HRTF), AMBISONICS or
                                 AMBISONIC_BINAURAL */
  /* further listeners, traced in the same pass as the first (docs/dynamic.md): listener
     index i + 1 is additional_listeners[i]; see dpc_engine_select_listener */
  const dpc_listener* additional_listeners; /**< NULL, or additional_listener_count entries */
  int additional_listener_count;            /**< 0..63 (a scene has at most 64 listeners) */
  /* source directivity: NULL (the default) makes every source omni; else source_count
     entries, entry i for sources[i] */
  const dpc_source_directivity* source_directivities;
  /* many sources (docs/performance.md, "Many sources"; since 0.4.0) */
  float cache_pool_mb; /**< DPC memory budget of the whole engine, MB, (0, 65536], or
                            DPC_CACHE_POOL_AUTO (the default since 0.7.0): sized by the scene,
                            4 MB per source-listener pair at 4096 rays, tau 1 s, 15 frames/s
                            (scaled with them), at least 128 (docs/scene-format.md); every
                            pair's cache grows from it; a pool below the tables the pairs'
                            caches start with is refused (DPC_ERR_INPUT naming
                            cache_pool_mb) */
  dpc_rendering rendering; /**< DPC_RENDERING_AUTO (default), _PER_SOURCE or _HYBRID */
  int late_buses;          /**< hybrid rendering: late buses per listener, [1, 64]; default 4 */
  float cluster_angle_degrees; /**< hybrid rendering: a cluster's angular radius as seen from
                                    the listener, degrees, (0, 180]; default 30 */
  int ambisonic_order; /**< AmbiX outputs' order N, [1, 7]; default 3 */
  /* Since 0.7.0. */
  const dpc_material_transmission* material_transmissions; /**< NULL (the default): every
                                     material opaque; else material_count entries */
  int exact_order; /**< exact early specular paths up to this reflection order (docs/design.md
                        "Exact early specular paths"), [0, 6], 0 disables them; default 3 */
  int reserved_0_7; /**< 0.7.0's tail padding, named so that 0.8.0's fields begin at 0.7.0's
                         size; ignored, dpc_scene_data_init sets it 0 */
  /* Since 0.8.0: the scene file's propagation keys of the same names (docs/scene-format.md). */
  dpc_estimator estimator; /**< DPC_ESTIMATOR_DPC (default) or _PATH_TRACING */
  dpc_tracing tracing;     /**< DPC_TRACING_AUTO (default), _FROM_SOURCES or _FROM_LISTENERS */
  int reflection_scattering; /**< nonzero (the default): with diffraction, a ray off a face
                                  standing free and smaller than its Fresnel zone keeps Rindel's
                                  share specular and scatters the rest (docs/design.md); 0: it
                                  reflects whole, as off a wall. No effect with diffraction 0 */
  float roulette_threshold_db; /**< Russian roulette (Arvo & Kirk 1990): a ray below this level
                                    of its initial energy in every band goes on with
                                    probability 0.1 at 10x its energy, or ends (unbiased);
                                    dB, [-300, 0]; default -60 */
} dpc_scene_data;

/** Any thread; no allocation. Fills the first struct_size bytes of *data, a layout this
 *  library knows (the growth rule): struct_size; zero mesh, materials and sources; listener at
 *  the origin; every other field the scene-file default (docs/scene-format.md). Errors:
 *  DPC_ERR_INVALID_ARGUMENT (NULL), DPC_ERR_VERSION (an unknown size: nothing written). Since
 *  0.7.0; call it through the dpc_scene_data_init macro. */
DPC_API dpc_status dpc_scene_data_init_sized(dpc_scene_data* data, size_t struct_size);
/** The 0.6.0 entry point, for programs compiled against 0.6.0 and earlier: fills the 0.6.0
 *  layout. NULL is ignored. */
DPC_API void(dpc_scene_data_init)(dpc_scene_data* data);
/** Fills *data for this header's layout (dpc_scene_data_init_sized). */
#define dpc_scene_data_init(data) dpc_scene_data_init_sized((data), sizeof(dpc_scene_data))

/** Control thread. Builds an engine from a scene described in memory; everything is copied, the
 *  caller's arrays may be freed on return. The same data as a scene file gives the same engine
 *  (same seed: same impulse responses). Allocates. Errors: DPC_ERR_INVALID_ARGUMENT (NULL
 *  pointers), DPC_ERR_VERSION (data->struct_size or options->struct_size), DPC_ERR_INPUT (a
 *  value outside the scene file's range, an index out of bounds, a coordinate beyond
 *  +-10^6 m or not finite, only degenerate triangles: dpc_last_error() names the field, e.g.
 *  "dpc_scene_data: materials[1].absorption[3]: ..."), DPC_ERR_INTERNAL. `options` as for
 *  dpc_engine_create_from_file (may be NULL). */
DPC_API dpc_status dpc_engine_create_from_data(const dpc_scene_data* data,
                                               const dpc_engine_options* options, dpc_engine** out);

/** Control thread. Stops the threads if running and frees everything. NULL is ignored. No
 *  other call on this engine may overlap it or follow it (the lifetime rule at the top of this
 *  header: calls found inside are waited for and counted in a logged warning, calls arriving
 *  meanwhile get DPC_ERR_STATE). Destroying the last engine also joins TBB's worker threads
 *  (which run the propagation's parallel work) unless other code in the process still uses
 *  TBB, so that a plugin host may unload libdpc afterwards. */
DPC_API void dpc_engine_destroy(dpc_engine* engine);

/** Control thread. Starts the propagation thread (idempotent). Allocates (thread creation).
 *  Errors: DPC_ERR_INVALID_ARGUMENT (NULL), DPC_ERR_INTERNAL (the thread could not start). */
DPC_API dpc_status dpc_engine_start(dpc_engine* engine);
/** Control thread. Stops and joins the propagation thread (idempotent). Errors:
 *  DPC_ERR_INVALID_ARGUMENT (NULL). */
DPC_API dpc_status dpc_engine_stop(dpc_engine* engine);

/** Control thread, while the propagation thread is stopped (before dpc_engine_start or after
 *  dpc_engine_stop): runs one propagation frame now, on the calling thread, for the current
 *  listener and source poses, and hands its impulse responses to the audio side as the
 *  propagation thread would. For hosts that render faster or slower than real time
 *  (offline bounces, tests): same seed and same calls give the same bits. Allocates while the
 *  path cache grows. Errors: DPC_ERR_INVALID_ARGUMENT (NULL), DPC_ERR_STATE (running). */
DPC_API dpc_status dpc_engine_step(dpc_engine* engine);

/** Any thread except the audio thread (it may wait briefly for a lock the propagation thread
 *  holds while it copies; the propagation thread skips a frame's copy rather than wait for
 *  a copy in progress, but at most every other frame, so a reader that copies without pause
 *  still sees every other frame or newer). Copies the pressure impulse response of the
 *  newest propagation frame for `source` (scene order) and output
 *  channel `channel` (< dpc_engine_ir_channels) into out[0..capacity): linear pressure
 *  per sample at dpc_engine_sample_rate(), sample 0 = emission time; its energy per octave
 *  band follows the energy response (dpc_engine_copy_energy_response). *length (if not NULL)
 *  receives the IR's full length in samples; min(capacity, length) samples are copied (out
 *  may be NULL with capacity 0 to ask for the length). *frame (if not NULL) receives the
 *  propagation frame count it came from. No allocation on success. Errors:
 *  DPC_ERR_INVALID_ARGUMENT (NULL engine, index out of range, out NULL with capacity > 0:
 *  dpc_last_error() names the argument), DPC_ERR_STATE (no frame run yet). */
DPC_API dpc_status dpc_engine_copy_impulse_response(dpc_engine* engine, int source, int channel,
                                                    float* out, size_t capacity, size_t* length,
                                                    uint64_t* frame);

/** As dpc_engine_copy_impulse_response, for the energy response of `source` behind it: bin k
 *  holds the intensity arriving with a delay in [k, k+1) * *bin_seconds (1 ms), per octave
 *  band, relative to the source's emitted power, in 1/m^2 (a direct sound at distance r adds
 *  1/(4 pi r^2) before air absorption); direct sound, exact early specular paths (exact_order)
 *  and the estimated reflections together, each in the bin of its delay. A source
 *  played from an attached bake (dpc_engine_attach_bake) gives the bake's response
 *  interpolated at the listener plus the live direct sound and exact paths, the response its IR is
 *  synthesised from (it is not traced). out receives bin-major data out[k * DPC_BANDS + b] for
 *  min(capacity_bins, *bins) bins. */
DPC_API dpc_status dpc_engine_copy_energy_response(dpc_engine* engine, int source, float* out,
                                                   size_t capacity_bins, size_t* bins,
                                                   double* bin_seconds, uint64_t* frame);

/** Audio thread. Renders `frames` frames (1..8192, may vary from call to call) into
 *  outputs[0..dpc_engine_output_channels()), each a buffer of `frames` samples.
 *  inputs: NULL to play the scene's own dry signals, or one mono buffer of `frames` samples per
 *  source (scene order) holding the host's dry signal (pressure, full scale 1), scaled by the
 *  source's gain_db as a scene's own signal is; a sample that is not finite or beyond +-1e6
 *  plays as 0 and is counted (dpc_stats.input_samples_replaced): one such sample would
 *  otherwise fill the convolution's history and silence the output for the IR's length. The
 *  output passes a safety limiter (no look-ahead, ceiling -0.1 dBFS, 50 ms release; frames it
 *  attenuates are counted in dpc_stats.limited_frames): an output meant to exceed full scale
 *  is lowered, not clipped; lower the sources' gain_db for headroom. The
 *  engine convolves in fixed blocks of
 *  dpc_engine_block_size() frames; a FIFO between the host's calls and those blocks adds a
 *  constant latency of dpc_engine_latency_frames() frames whatever the call pattern. Never
 *  allocates, locks, logs or waits. Errors (no message set): DPC_ERR_INVALID_ARGUMENT (null
 *  engine, outputs or outputs[c], or inputs[s] NULL in a non-NULL inputs: nothing rendered,
 *  the buffers untouched; frames outside 1..8192: nothing rendered, counted in
 *  dpc_stats.rejected_callbacks). */
DPC_API dpc_status dpc_engine_process(dpc_engine* engine, const float* const* inputs,
                                      float* const* outputs, int frames);

/** Any thread, no allocation. Fixed properties of the engine (from the scene and the
 *  creation options); each returns 0 for a NULL engine. */
DPC_API int dpc_engine_sample_rate(const dpc_engine* engine);     /**< Hz */
DPC_API int dpc_engine_block_size(const dpc_engine* engine);      /**< engine block, frames */
/** Channels dpc_engine_process writes: 1 mono, 2 stereo or binaural (left, right),
 *  (order + 1)^2 AmbiX (ACN order), 2 for AMBISONIC_BINAURAL (left, right). */
DPC_API int dpc_engine_output_channels(const dpc_engine* engine);
/** Channels of the impulse responses (dpc_engine_copy_impulse_response): as
 *  dpc_engine_output_channels, except (order + 1)^2 AmbiX channels for AMBISONIC_BINAURAL (in
 *  the reference head frame, yaw and pitch 0). Since 0.4.0. */
DPC_API int dpc_engine_ir_channels(const dpc_engine* engine);
DPC_API int dpc_engine_source_count(const dpc_engine* engine);
DPC_API int dpc_engine_object_count(const dpc_engine* engine); /**< moving objects */
/** Latency process() adds to the host's signal, frames (one engine block). */
DPC_API int dpc_engine_latency_frames(const dpc_engine* engine);

/** Counters and last-frame measurements of a running engine. The caller sets struct_size =
 *  sizeof(dpc_stats) before dpc_engine_get_stats, which writes no further (the growth rule). */
typedef struct dpc_stats {
  size_t struct_size;            /**< sizeof(dpc_stats), set by the caller */
  uint64_t frames;               /**< propagation frames run */
  double frame_ms;               /**< duration of the last propagation frame, ms */
  double rays_per_second;        /**< since the previous dpc_engine_get_stats call */
  uint64_t cache_entries;        /**< diffuse path cache entries after the last frame */
  uint64_t cache_bytes;          /**< heap bytes held by the caches, summed over sources */
  uint64_t cache_budget_bytes;   /**< their memory budget, summed over sources */
  uint64_t cache_merged_entries; /**< path entries merged into coarse delay bins, cumulative */
  double cache_merged_energy_fraction; /**< largest per-source share of the response's energy
                                            read from merged entries, [0, 1] */
  uint64_t irs_applied;                /**< impulse-response sets that reached the convolvers */
  uint64_t irs_dropped;                /**< superseded before the audio thread applied them */
  double ir_age_ms;                    /**< age of the impulse response playing, ms */
  uint64_t blocks;                     /**< engine blocks rendered */
  uint64_t nan_blocks;                 /**< blocks zeroed because they held NaN or infinity */
  uint64_t late_callbacks;             /**< process() calls that took longer than the audio they
                                            produced (a device would have underrun) */
  uint64_t rejected_callbacks;         /**< process() calls with frames outside 1..8192 */
  /* Adaptive rays (docs/live.md): while running, the propagation thread traces fewer rays per
   * source than the scene's rays_per_frame when a frame would not fit in 1 / frame_rate. */
  int32_t rays_per_frame;     /**< rays per source traced by the last frame (0 before one) */
  int32_t rays_per_frame_min; /**< fewest rays per source of any frame so far (0 before one) */
  uint64_t reduced_frames;    /**< frames traced with fewer rays than the scene's */
  /* Baked playback (dpc_engine_attach_bake; since 0.3.0), cumulative, 0 without a bake. */
  uint64_t baked_responses; /**< source responses played from the bake */
  uint64_t bake_fallbacks;  /**< frames whose listener saw no probe (played live instead) */
  /* Since 0.6.0, cumulative. */
  uint64_t input_samples_replaced; /**< host input samples (dpc_engine_process inputs) played
                                        as 0: not finite, or beyond +-1e6 (a dry signal's limit) */
  uint64_t limited_frames;         /**< output frames the safety limiter attenuated */
  /* Since 0.7.0. */
  double dropped_energy_fraction; /**< last frame, selected listener: the largest per-source
                                       share of the response's energy that arrived after the
                                       IR length (not heard; lengthen ir_length), [0, 1] */
  /* Since 0.9.0. */
  double max_order_energy_fraction; /**< last frame, selected listener: the largest per-source,
                                         per-band share of the emitted energy that rays still
                                         carried when max_order ended them (lost to the
                                         response; when above DPC_MAX_ORDER_WARN_FRACTION,
                                         raise max_order). A Monte Carlo estimate, in [0, 1]
                                         on average (Russian roulette's survivors carry 10
                                         times their energy); 0 before the first frame and for
                                         sources played from a bake */
} dpc_stats;

/** The share of emitted energy cut by max_order above which dpc-demo and the Python module
 *  warn (-40 dB: T30 reads a decay down to -35 dB, so a cut there shortens it). Since 0.9.0. */
#define DPC_MAX_ORDER_WARN_FRACTION 1e-4

/** Control thread (it updates the rays-per-second interval). No allocation. Fills the fields
 *  of *out within out->struct_size (all but struct_size). Errors: DPC_ERR_INVALID_ARGUMENT
 *  (NULL), DPC_ERR_VERSION (out->struct_size is not a dpc_stats layout this library knows:
 *  nothing written), DPC_ERR_STATE (being destroyed). */
DPC_API dpc_status dpc_engine_get_stats(dpc_engine* engine, dpc_stats* out);

/* Baked playback (docs/bake.md; since 0.3.0). A bake (dpc-bake, HDF5) holds each static
 * source's energy response at a grid of probes; an engine with a bake attached plays every
 * source that stands at its baked position (within 1 cm) from it: the late response is
 * interpolated between the probes the listener can see (never across a wall; with none visible
 * the frame falls back to the live simulation), the direct sound, its occlusion and the exact
 * early paths stay live, and the source is not traced. Moved sources keep the live simulation
 * (their path caches restarted when they leave the baked position). */

/** An opened bake, checked against one engine's scene. Opaque; immutable once opened, so one
 *  bake may be attached to several engines of the same scene. */
typedef struct dpc_bake dpc_bake;

/** Control thread. Reads the bake at bake_path whole into memory (allocates: 44.8 kB per
 *  probe and source per second of response), verifies every probe's checksums and checks it
 *  against the engine's scene. Errors: DPC_ERR_INVALID_ARGUMENT (NULL); DPC_ERR_INPUT, with the
 *  one-line message of dpc_last_error() naming the file and the field: a missing, truncated,
 *  damaged or corrupt file (a probe whose checksum fails names its dataset), another format or
 *  version (version), a dataset of the wrong shape, a bake of another scene or of other
 *  settings: the settings hash group that differs (hash_geometry, hash_materials,
 *  hash_sources, hash_physics; ir_length_s for another response length: docs/bake-format.md),
 *  an incomplete bake (complete), another number of sources (sources/position);
 *  DPC_ERR_UNSUPPORTED when the library was built without HDF5. *out is NULL on error. */
DPC_API dpc_status dpc_bake_open(const dpc_engine* engine, const char* bake_path,
                                 dpc_bake** out);
/** Control thread. The bake's probes, or -1 for NULL. */
DPC_API int dpc_bake_probe_count(const dpc_bake* bake);
/** Control thread. Releases the handle; an engine it is attached to keeps its own reference.
 *  NULL is ignored. */
DPC_API void dpc_bake_destroy(dpc_bake* bake);
/** Control thread, while the engine is not running (after create or stop): plays the engine's
 *  static sources from `bake` from the next frame on, replacing a bake attached before; NULL
 *  detaches it. Allocates the interpolator's tables. Errors: DPC_ERR_INVALID_ARGUMENT (NULL
 *  engine, or a bake whose scene differs from the engine's), DPC_ERR_STATE (running). */
DPC_API dpc_status dpc_engine_attach_bake(dpc_engine* engine, const dpc_bake* bake);

#ifdef __cplusplus
}
#endif

#include "dpc/dpc_poses.h"

#endif /* DPC_DPC_H */
