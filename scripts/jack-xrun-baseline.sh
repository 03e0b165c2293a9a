#!/usr/bin/env bash
# How many xruns does this machine give a JACK client that does nothing? Runs a do-nothing
# client (its process callback writes silence) on a dummy JACK server (scripts/jack-headless.sh:
# jackd -R where SCHED_FIFO is granted, 128 frames unless JACK_PERIOD says otherwise) for S
# seconds, with N busy loops at normal priority beside it, or with a load command run over and
# over beside it (after --: e.g. an offline dpc-demo render, the same tracing a live session
# does), and prints "cycles C xruns X late L": L counts the client's own callbacks that took
# longer than the period from start to end (a callback this small is only late when the
# machine stopped it). The baseline against which dpc-demo's live xruns are read (docs/live.md,
# tests/apps/live_jack_test.sh): xruns a do-nothing client also gets are the machine's (timer
# wake-ups, a VM's host descheduling it), not the engine's.
#
# WORK_PERCENT=P (default 0) makes the callback do a constant amount of arithmetic, P % of the
# period as the client times it when it starts (the fastest of five timings; beside busy loops
# or a load command it may come out lighter than P: read the printed median), a dependent
# chain of float operations: no memory traffic, no branch that depends on data. The client then also prints
# "load median M p99 Q p99.9 R max X" (% of the period, from the clock at the callback's
# start and end), one line before the counts: the spread of a callback whose work never
# changes is the machine's, the instrument against which an engine's callback load tail
# (its p99.9 and maximum) is read. STREAM_KB=K (default 0) adds a memory load like a
# convolver's: each callback also sums the next K kB of a 64 MB pool (cyclically), so the
# callback's data comes from memory shared with the machine's other work, not from its caches.
#
#   scripts/jack-xrun-baseline.sh [SECONDS] [BUSY_LOOPS] [-- LOAD COMMAND...]   (defaults 60, 2)
#
# Needs gcc and JACK's headers (libjack-jackd2-dev, which Debian's PortAudio -dev pulls in).
set -euo pipefail
seconds=${1:-60}
busy=${2:-2}
load=()
if (($# > 2)); then
  if [[ $3 != -- ]]; then
    echo "jack-xrun-baseline: the third argument must be -- before a load command" >&2
    exit 2
  fi
  load=("${@:4}")
fi
here=$(cd "$(dirname "$0")" && pwd)
work=$(mktemp -d)
pids=()
cleanup() {
  # Each helper leads its own process group (setsid): the group goes, load command included.
  for p in "${pids[@]}"; do kill -- "-$p" 2>/dev/null || kill "$p" 2>/dev/null || true; done
  rm -rf "$work"
}
trap cleanup EXIT
cat >"$work/client.c" <<'C'
#include <jack/jack.h>
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
int main(int argc, char** argv) {
  const int seconds = argc > 1 ? atoi(argv[1]) : 60;
  jack_client_t* c = jack_client_open("xrun-baseline", JackNoStartServer, NULL);
  if (!c) {
    fprintf(stderr, "jack-xrun-baseline: no JACK server\n");
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
    fprintf(stderr, "jack-xrun-baseline: could not activate the client\n");
    return 1;
  }
  sleep((unsigned)seconds);
  jack_deactivate(c);  /* no callback writes the histogram while it is read */
  if (workIterations > 0 || streamFloats > 0) {
    const unsigned total = (unsigned)atomic_load(&cycles);
    printf("load median %.2f p99 %.2f p99.9 %.2f max %.2f\n", quantile(0.5, total),
           quantile(0.99, total), quantile(0.999, total), quantile(1.0, total));
  }
  printf("cycles %d xruns %d late %d\n", atomic_load(&cycles), atomic_load(&xruns),
         atomic_load(&late));
  jack_client_close(c);
  return 0;
}
C
gcc -O2 -o "$work/client" "$work/client.c" -ljack
if ((${#load[@]})); then
  setsid bash -c 'while :; do "$@" >/dev/null 2>&1 || true; done' load "${load[@]}" &
  pids+=($!)
  echo "jack-xrun-baseline: client (work ${WORK_PERCENT:-0} % of the period, ${STREAM_KB:-0} kB read) for ${seconds} s beside: ${load[*]}" >&2
else
  for ((i = 0; i < busy; ++i)); do
    setsid bash -c 'while :; do :; done' &
    pids+=($!)
  done
  echo "jack-xrun-baseline: client (work ${WORK_PERCENT:-0} % of the period, ${STREAM_KB:-0} kB read) for ${seconds} s, ${busy} busy loops beside it" >&2
fi
"$here/jack-headless.sh" "$work/client" "$seconds"
