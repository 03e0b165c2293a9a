/* Renders SCENE.json through the dpc C API into OUT.wav: the listener walks 3 m along +x
 * while the scene's dry signals are fed block by block through dpc_engine_process. The WAV
 * has the engine's output channels, whatever the scene's format (2 for binaural, 16 for
 * third-order AmbiX).
 * Usage: play_scene SCENE.json OUT.wav */
#include <dpc/dpc.h>
#include <sndfile.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

int main(int argc, char** argv) {
  if (argc != 3) {
    fprintf(stderr, "usage: %s SCENE.json OUT.wav\n", argv[0]);
    return 2;
  }
  /* The library must serve this header: the same major version, not older (dpc.h). */
  if (!DPC_VERSION_COMPATIBLE(dpc_version())) {
    fprintf(stderr, "libdpc %lu.%lu is older than dpc.h %s or of another major version\n",
            dpc_version() >> 16, (dpc_version() >> 8) & 0xff, DPC_VERSION_STRING);
    return 1;
  }
  dpc_engine* engine = NULL;
  if (dpc_engine_create_from_file(argv[1], NULL, &engine) != DPC_OK) {
    fprintf(stderr, "%s\n", dpc_last_error());
    return 1;
  }
  const int rate = dpc_engine_sample_rate(engine), block = dpc_engine_block_size(engine);
  const int channels = dpc_engine_output_channels(engine);
  SF_INFO info = {0};
  info.samplerate = rate;
  info.channels = channels;
  info.format = SF_FORMAT_WAV | SF_FORMAT_FLOAT;
  SNDFILE* out = sf_open(argv[2], SFM_WRITE, &info);
  if (!out) {
    fprintf(stderr, "%s: %s\n", argv[2], sf_strerror(NULL));
    dpc_engine_destroy(engine);
    return 1;
  }
  /* One output buffer per channel the engine writes. */
  float* planar = calloc((size_t)block * channels, sizeof(float));
  float* interleaved = calloc((size_t)block * channels, sizeof(float));
  float** outputs = calloc((size_t)channels, sizeof(float*));
  if (!planar || !interleaved || !outputs) {
    fprintf(stderr, "out of memory\n");
    return 1;
  }
  for (int c = 0; c < channels; ++c) outputs[c] = planar + (size_t)c * block;

  /* Facing +x (the rest pose), ears 1.6 m above the floor. */
  dpc_pose pose = {{3.5f, 1.6f, 1.5f}, {0.f, 0.f, 0.f, 1.f}};
  dpc_engine_place_listener(engine, 0, &pose);
  dpc_engine_start(engine);
  const int blocks = 4 * rate / block; /* 4 s */
  for (int b = 0; b < blocks; ++b) {
    /* Move the listener, then wait (as a sound card would) for one block period. */
    pose.position[0] = 3.5f + 3.f * (float)b / (float)blocks;
    dpc_engine_place_listener(engine, 0, &pose);
    struct timespec period = {0, (long)(1e9 * block / rate)};
    nanosleep(&period, NULL);
    dpc_engine_process(engine, NULL, outputs, block);
    for (int i = 0; i < block; ++i)
      for (int c = 0; c < channels; ++c) interleaved[i * channels + c] = outputs[c][i];
    sf_writef_float(out, interleaved, block);
  }
  dpc_engine_stop(engine);
  dpc_stats stats;
  stats.struct_size = sizeof stats;
  dpc_engine_get_stats(engine, &stats);
  printf("%llu propagation frames, %llu impulse responses applied, %llu blocks\n",
         (unsigned long long)stats.frames, (unsigned long long)stats.irs_applied,
         (unsigned long long)stats.blocks);
  sf_close(out);
  free(outputs);
  free(planar);
  free(interleaved);
  dpc_engine_destroy(engine);
  return 0;
}
