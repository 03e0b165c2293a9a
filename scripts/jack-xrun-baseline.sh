#!/usr/bin/env bash
# How many xruns does this machine give a JACK client that does nothing? Runs the reference
# client (scripts/jack-reference-client.c: its callback writes silence) on a dummy JACK server
# (scripts/jack-headless.sh: jackd -R where SCHED_FIFO is granted, 128 frames unless
# JACK_PERIOD says otherwise) for S seconds, with N busy loops at normal priority beside it, or
# with a load command run over and over beside it (after --: e.g. an offline dpc-demo render,
# the same tracing a live session does), and prints the client's "cycles C xruns X late L": L
# counts its callbacks that took longer than the period from start to end (a callback this
# small is only late when the machine stopped it). Xruns a do-nothing client also gets are the
# machine's (timer wake-ups, a VM's host descheduling it), not an engine's (docs/live.md).
#
# WORK_PERCENT=P and STREAM_KB=K give the callback constant arithmetic and memory traffic (see
# the client's header); it then also prints "load mean A median M p99 Q p99.9 R max X" (% of
# the period) one line before the counts: the spread of a callback whose work never changes
# is the machine's, the instrument against which an engine's callback load tail is read.
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
gcc -O2 -o "$work/client" "$here/jack-reference-client.c" -ljack
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
