/* A fault for tests/apps/live_jack_test.sh's negative control, loaded with LD_PRELOAD into the
 * client under test: every OVERRUN_EVERY-th process callback (default 50) busy-waits
 * OVERRUN_MS milliseconds (default 4, longer than a 128-frame period at 48 kHz) after the
 * client's own callback, as an engine that overran its block would. The live check must then
 * fail on the client's late callbacks and xruns. */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <jack/jack.h>
#include <stdlib.h>
#include <time.h>

static JackProcessCallback wrapped;
static void* wrappedArg;
static long every = 50;
static double overrunSeconds = 0.004;
static long calls;

static double now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int overrunning(jack_nframes_t frames, void* arg) {
  (void)arg;
  const int status = wrapped(frames, wrappedArg);
  if (++calls % every == 0) {
    const double until = now() + overrunSeconds;
    while (now() < until) {
    }
  }
  return status;
}

int jack_set_process_callback(jack_client_t* client, JackProcessCallback callback, void* arg) {
  typedef int (*Real)(jack_client_t*, JackProcessCallback, void*);
  const Real real = (Real)dlsym(RTLD_NEXT, "jack_set_process_callback");
  const char* n = getenv("OVERRUN_EVERY");
  const char* ms = getenv("OVERRUN_MS");
  if (n && atol(n) > 0) every = atol(n);
  if (ms && atof(ms) > 0.0) overrunSeconds = atof(ms) / 1000.0;
  wrapped = callback;
  wrappedArg = arg;
  return real(client, overrunning, NULL);
}
