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
static atomic_int cycles, xruns, late;
static jack_port_t* port;
static double periodSeconds;
static double now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}
static int process(jack_nframes_t n, void* arg) {
  (void)arg;
  const double start = now();
  memset(jack_port_get_buffer(port, n), 0, n * sizeof(float));
  atomic_fetch_add(&cycles, 1);
  if (now() - start > periodSeconds) atomic_fetch_add(&late, 1);
  return 0;
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
  port = jack_port_register(c, "out", JACK_DEFAULT_AUDIO_TYPE, JackPortIsOutput, 0);
  jack_set_process_callback(c, process, NULL);
  jack_set_xrun_callback(c, xrun, NULL);
  if (!port || jack_activate(c) != 0) {
    fprintf(stderr, "jack-xrun-baseline: could not activate the client\n");
    return 1;
  }
  sleep((unsigned)seconds);
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
  echo "jack-xrun-baseline: do-nothing client for ${seconds} s beside: ${load[*]}" >&2
else
  for ((i = 0; i < busy; ++i)); do
    setsid bash -c 'while :; do :; done' &
    pids+=($!)
  done
  echo "jack-xrun-baseline: do-nothing client for ${seconds} s, ${busy} busy loops beside it" >&2
fi
"$here/jack-headless.sh" "$work/client" "$seconds"
