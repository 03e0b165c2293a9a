/* A C program of the C API's growth rule (dpc.h, "Versions and growth rule"): compiled once
 * against the installed dpc.h and once against a previous release's, it runs against the
 * installed library and must print the same lines. It builds a 6 x 4 x 3 m box in code, runs
 * three frames and checks what it gets: no byte written past each struct of its header's
 * layout, three frames counted, and the direct sound of the source 2 m away in its 1 ms bin
 * with the energy 1 / (4 pi r^2) (dpc_engine_copy_energy_response), nothing before it.
 * Prints its struct sizes to stderr and the results to stdout; exit status 1 on any failure.
 * Usage: layout_client */
#include <dpc/dpc.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#define CANARY 0xA5
#define SPARE 64

/* A struct of this header's layout followed by SPARE bytes no call may write. */
typedef union {
  unsigned char bytes[sizeof(dpc_scene_data) + SPARE];
  dpc_scene_data data;
} guarded_data;
typedef union {
  unsigned char bytes[sizeof(dpc_engine_options) + SPARE];
  dpc_engine_options options;
} guarded_options;
typedef union {
  unsigned char bytes[sizeof(dpc_stats) + SPARE];
  dpc_stats stats;
} guarded_stats;

static int intact(const unsigned char* bytes, size_t size, const char* what) {
  for (size_t i = size; i < size + SPARE; ++i)
    if (bytes[i] != CANARY) {
      fprintf(stderr, "layout_client: %s: byte %zu past the struct was written\n", what, i);
      return 0;
    }
  return 1;
}

static int check(dpc_status s, const char* call) {
  if (s == DPC_OK) return 1;
  fprintf(stderr, "layout_client: %s: %s\n", call, dpc_last_error());
  return 0;
}

static const float kVertices[] = {0, 0, 0, 6, 0, 0, 6, 3, 0, 0, 3, 0,
                                  0, 0, 4, 6, 0, 4, 6, 3, 4, 0, 3, 4};
static const uint32_t kIndices[] = {0, 1, 2, 0, 2, 3, 4, 6, 5, 4, 7, 6, 0, 4, 5, 0, 5, 1,
                                    3, 2, 6, 3, 6, 7, 0, 3, 7, 0, 7, 4, 1, 5, 6, 1, 6, 2};
static const uint32_t kMaterials[12] = {0};

/* The direct sound: energy per band in the bin of the arrival, 0 before it. */
static int checkDirect(dpc_engine* e) {
  static float energy[4000 * DPC_BANDS];
  size_t bins = 0;
  double binSeconds = 0.0;
  if (!check(dpc_engine_copy_energy_response(e, 0, energy, 4000, &bins, &binSeconds, NULL),
             "dpc_engine_copy_energy_response"))
    return 0;
  const double r = 2.0, c = 331.3 * sqrt(1.0 + 20.0 / 273.15); /* dry air at 20 C */
  const size_t arrival = (size_t)(r / c / binSeconds);
  double before = 0.0;
  for (size_t k = 0; k < arrival * DPC_BANDS; ++k) before += energy[k];
  const double expected = 1.0 / (4.0 * 3.14159265358979 * r * r);
  const double ratio = energy[arrival * DPC_BANDS + 3] / expected; /* 500 Hz */
  printf("direct sound: bin %zu, 500 Hz energy %.4f of 1/(4 pi r^2), %.3g before it\n", arrival,
         ratio, before);
  /* 500 Hz air absorption over 2 m is below 0.01 dB; no reflection reaches this bin (the
   * nearest, off the floor, travels 3.6 m). */
  return before == 0.0 && fabs(ratio - 1.0) < 0.01;
}

static int run(dpc_engine* e) {
  for (int i = 0; i < 3; ++i)
    if (!check(dpc_engine_step(e), "dpc_engine_step")) return 0;
  guarded_stats s;
  memset(s.bytes, CANARY, sizeof s.bytes);
  s.stats.struct_size = sizeof(dpc_stats);
  if (!check(dpc_engine_get_stats(e, &s.stats), "dpc_engine_get_stats") ||
      !intact(s.bytes, sizeof(dpc_stats), "dpc_stats"))
    return 0;
  printf("frames %llu, rays per frame %d, struct_size kept %d\n",
         (unsigned long long)s.stats.frames, (int)s.stats.rays_per_frame,
         s.stats.struct_size == sizeof(dpc_stats));
  size_t length = 0;
  float ir[12000];
  if (!check(dpc_engine_copy_impulse_response(e, 0, 0, ir, 12000, &length, NULL),
             "dpc_engine_copy_impulse_response"))
    return 0;
  double sum = 0.0;
  for (size_t n = 0; n < 12000 && n < length; ++n) sum += (double)ir[n] * ir[n];
  printf("impulse response: %zu samples, energy of the first 0.25 s %.9g\n", length, sum);
  return s.stats.frames == 3 && checkDirect(e);
}

int main(void) {
  fprintf(stderr, "layout_client: dpc.h %s (dpc_engine_options %zu, dpc_scene_data %zu, "
          "dpc_stats %zu bytes), libdpc %lu.%lu.%lu\n", DPC_VERSION_STRING,
          sizeof(dpc_engine_options), sizeof(dpc_scene_data), sizeof(dpc_stats),
          dpc_version() >> 16, (dpc_version() >> 8) & 0xff, dpc_version() & 0xff);
  guarded_data d;
  memset(d.bytes, CANARY, sizeof d.bytes);
  dpc_scene_data_init(&d.data);
  guarded_options o;
  memset(o.bytes, CANARY, sizeof o.bytes);
  dpc_engine_options_init(&o.options);
  if (!intact(d.bytes, sizeof(dpc_scene_data), "dpc_scene_data_init") ||
      !intact(o.bytes, sizeof(dpc_engine_options), "dpc_engine_options_init"))
    return 1;
  const dpc_material walls = {"walls", {0.1f, 0.1f, 0.1f, 0.1f, 0.1f, 0.1f, 0.1f, 0.1f}, 0.2f};
  const dpc_source source = {{2.f, 1.5f, 2.f}, 0.f, NULL, 0, 0};
  const dpc_mesh mesh = {kVertices, 8, kIndices, 12, kMaterials};
  d.data.mesh = mesh;
  d.data.materials = &walls;
  d.data.material_count = 1;
  d.data.sources = &source;
  d.data.source_count = 1;
  d.data.listener_position[0] = 4.f;
  d.data.listener_position[1] = 1.5f;
  d.data.listener_position[2] = 2.f;
  o.options.rays_per_frame = 2000;
  o.options.host_inputs_only = 1;
  dpc_engine* e = NULL;
  if (!check(dpc_engine_create_from_data(&d.data, &o.options, &e), "dpc_engine_create_from_data"))
    return 1;
  const int ok = run(e);
  dpc_engine_destroy(e);
  return ok ? 0 : 1;
}
