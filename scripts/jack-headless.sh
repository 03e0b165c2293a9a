#!/usr/bin/env bash
# Runs a command with a JACK server on the dummy backend (no sound card needed), then stops
# the server and exits with the command's status.
#
#   scripts/jack-headless.sh COMMAND [ARGS...]
#   scripts/jack-headless.sh build-dev/tests/audio_device_test "[jack]" -s
#   scripts/jack-headless.sh build-dev/dpc-demo scenes/shoebox.json --device jack:system
#
# Environment: JACK_RATE (default 48000), JACK_PERIOD (frames, default 128), JACK_LOG (a path:
# the server's log is written there and kept, e.g. to read which client an xrun named). The
# command sees DPC_JACK=1 (the [jack] playback tests run only then).
#
# Installs Debian's jackd2 if jackd is missing (non-interactively, answering "no" to
# realtime priority in debconf; jackd itself runs with -R when the machine grants SCHED_FIFO,
# see below). The server's log goes to a temporary file, printed if it fails to come up.
# The server is stopped by its process id, never by name.
set -euo pipefail

if [[ $# -lt 1 ]]; then
  echo "usage: $0 COMMAND [ARGS...]" >&2
  exit 2
fi

rate=${JACK_RATE:-48000}
period=${JACK_PERIOD:-128}

if ! command -v jackd >/dev/null 2>&1; then
  echo "jack-headless: installing jackd2" >&2
  sudo=""
  [[ $(id -u) -eq 0 ]] || sudo="sudo"
  echo "jackd2 jackd/tweak_rt_limits boolean false" | $sudo debconf-set-selections
  $sudo env DEBIAN_FRONTEND=noninteractive apt-get install -y -q jackd2 >&2
fi

# A server already running under the default name would make ours fail: say so.
if command -v jack_lsp >/dev/null 2>&1 && JACK_NO_START_SERVER=1 jack_lsp >/dev/null 2>&1; then
  echo "jack-headless: a JACK server is already running; using it" >&2
  DPC_JACK=1 "$@"
  exit $?
fi

"$(dirname "$0")/jack-reclaim.sh"
log=${JACK_LOG:-$(mktemp -t jackd-dummy.XXXXXX.log)}
# Real-time scheduling (-R: the process thread, and so dpc's audio callback, runs SCHED_FIFO)
# when this machine grants it (chrt succeeds) unless JACK_REALTIME=0; otherwise -r. The choice
# is printed so test logs say which one ran. Dummy backend, 2 playback ports by default.
rt=-r
if [[ ${JACK_REALTIME:-1} != 0 ]] && chrt -f 1 true 2>/dev/null; then rt=-R; fi
jackd "$rt" -d dummy -r "$rate" -p "$period" >"$log" 2>&1 &
pid=$!

stop_server() {
  if kill -0 "$pid" 2>/dev/null; then
    kill "$pid" 2>/dev/null || true
    wait "$pid" 2>/dev/null || true
  fi
}
trap stop_server EXIT

# Wait (at most 10 s) until the server answers.
up=0
for _ in $(seq 1 50); do
  if ! kill -0 "$pid" 2>/dev/null; then break; fi
  if JACK_NO_START_SERVER=1 jack_lsp >/dev/null 2>&1; then
    up=1
    break
  fi
  sleep 0.2
done
if [[ $up -ne 1 ]]; then
  echo "jack-headless: jackd did not come up within 10 s; its log ($log):" >&2
  cat "$log" >&2
  exit 1
fi
echo "jack-headless: jackd $rt (pid $pid) up: dummy backend, $rate Hz, $period frames; log $log" >&2

status=0
DPC_JACK=1 "$@" || status=$?

stop_server
trap - EXIT
[[ -n ${JACK_LOG:-} ]] || rm -f "$log"
exit $status
