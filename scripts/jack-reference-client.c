/* A reference JACK client: the machine's share of xruns and late callbacks, against which a
 * real client's are read (scripts/jack-xrun-baseline.sh, tests/apps/live_jack_test.sh). Its
 * process callback writes silence to one output port and, on request, does constant work:
 *   WORK_PERCENT=P  a dependent multiply-add chain timed to P % of the period when it starts
 *                   (the fastest of five timings: on a loaded machine it may come out lighter)
 *   STREAM_KB=K     also sums the next K kB of a 64 MB pool each callback (memory traffic)
 * A callback is late when it takes longer than the period from its start to its end.
 *
 *   jack-reference-client [SECONDS] [CLIENT_NAME]     (defaults 60, xrun-baseline)
 *
 * SIGTERM or SIGINT ends the run early, with the counts printed as at its end.
 *
 * Prints "load mean A median M p99 Q p99.9 R max X" (% of the period) when it works, then
 * "cycles C xruns X late L" (X: the server's xrun notifications, for any client). */
#include <jack/jack.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>
#define BINS 20000 /* load histogram: 0.05 % of the period per bin, up to 1000 % */
static atomic_int cycles, xruns, late;
static jack_port_t* port;
static double periodSeconds;
static long workIterations;
static volatile float sink;
static unsigned histogram[BINS];
static double loadSum; /* seconds inside callbacks, for the mean */
static double now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}
/* The constant work: a dependent multiply-add chain of `iterations` steps. */
static void work(long iterations) {
  float x = 1.0f;
  for (long i = 0; i < iterations; ++i) x = x * 0.999999f + 1e-7f;
  sink = x;
}
static long iterationsFor(double seconds) {
  long n = 1000000;
  double t;
  for (;;) {
    const double start = now();
    work(n);
    t = now() - start;
    if (t > 0.05) break;
    n *= 2;
  }
  /* The fastest of five timings: the idle machine's speed. */
  for (int k = 0; k < 5; ++k) {
    const double start = now();
    work(n);
    const double tk = now() - start;
    if (tk < t) t = tk;
  }
  return (long)((double)n * seconds / t);
}
#define POOL_FLOATS (16u << 20) /* 64 MB */
static float* pool;
static size_t streamFloats, poolAt;
static void stream(void) {
  float sum = 0.0f;
  for (size_t i = 0; i < streamFloats; ++i) {
    sum += pool[poolAt];
    if (++poolAt == POOL_FLOATS) poolAt = 0;
  }
  sink = sum;
}
static int process(jack_nframes_t n, void* arg) {
  (void)arg;
  const double start = now();
  memset(jack_port_get_buffer(port, n), 0, n * sizeof(float));
  if (workIterations > 0) work(workIterations);
  if (streamFloats > 0) stream();
  atomic_fetch_add(&cycles, 1);
  const double took = now() - start;
  loadSum += took;
  if (took > periodSeconds) atomic_fetch_add(&late, 1);
  long bin = (long)(took / periodSeconds * 100.0 / 0.05);
  histogram[bin < BINS ? bin : BINS - 1]++;
  return 0;
}
static double quantile(double q, unsigned total) {
  unsigned seen = 0;
  for (int b = 0; b < BINS; ++b) {
    seen += histogram[b];
    if (seen > 0 && (double)seen >= q * (double)total) return (b + 1) * 0.05;
  }
  return 1000.0;
}
static int xrun(void* arg) {
  (void)arg;
  atomic_fetch_add(&xruns, 1);
  return 0;
}
static volatile sig_atomic_t stopped;
static void stop(int signal) {
  (void)signal;
  stopped = 1;
}
int main(int argc, char** argv) {
  struct sigaction action;
  memset(&action, 0, sizeof action);
  action.sa_handler = stop;
  sigaction(SIGTERM, &action, NULL);
  sigaction(SIGINT, &action, NULL);
  const int seconds = argc > 1 ? atoi(argv[1]) : 60;
  const char* name = argc > 2 ? argv[2] : "xrun-baseline";
  jack_client_t* c = jack_client_open(name, JackNoStartServer | JackUseExactName, NULL);
  if (!c) {
    fprintf(stderr, "jack-reference-client: no JACK server\n");
    return 1;
  }
  periodSeconds = (double)jack_get_buffer_size(c) / (double)jack_get_sample_rate(c);
  const char* percent = getenv("WORK_PERCENT");
  if (percent && atof(percent) > 0.0)
    workIterations = iterationsFor(atof(percent) / 100.0 * periodSeconds);
  const char* kb = getenv("STREAM_KB");
  if (kb && atof(kb) > 0.0) {
    streamFloats = (size_t)(atof(kb) * 1024.0 / sizeof(float));
    pool = calloc(POOL_FLOATS, sizeof(float));
    if (!pool) return 1;
    for (size_t i = 0; i < POOL_FLOATS; ++i) pool[i] = (float)(i & 7);  /* touch every page */
  }
  port = jack_port_register(c, "out", JACK_DEFAULT_AUDIO_TYPE, JackPortIsOutput, 0);
  jack_set_process_callback(c, process, NULL);
  jack_set_xrun_callback(c, xrun, NULL);
  if (!port || jack_activate(c) != 0) {
    fprintf(stderr, "jack-reference-client: could not activate %s\n", name);
    return 1;
  }
  for (int s = 0; s < seconds && !stopped; ++s) sleep(1); /* a signal ends the sleep early */
  jack_deactivate(c);  /* no callback writes the histogram while it is read */
  if (workIterations > 0 || streamFloats > 0) {
    const unsigned total = (unsigned)atomic_load(&cycles);
    const double mean = total ? 100.0 * loadSum / (total * periodSeconds) : 0.0;
    printf("load mean %.2f median %.2f p99 %.2f p99.9 %.2f max %.2f\n", mean, quantile(0.5, total),
           quantile(0.99, total), quantile(0.999, total), quantile(1.0, total));
  }
  printf("cycles %d xruns %d late %d\n", atomic_load(&cycles), atomic_load(&xruns),
         atomic_load(&late));
  jack_client_close(c);
  return 0;
}
