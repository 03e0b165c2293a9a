#!/usr/bin/env bash
# A live session with --reconnect outlives its audio server: dpc-demo plays the shoebox on a
# JACK server of its own (dummy backend, tests/apps/jack_private_server.sh), recording and
# writing --stats, and the server is killed (SIGTERM) while it plays.
# 1. The server comes back 2.5 s later: dpc-demo says it reopens the device, plays on to the
#    end of its --duration and exits 0; the stats count one reconnection; the recording holds
#    more than was played before the kill (what was played after it too), is finite, and is
#    not silent from 3.5 to 7 s (sound after the reconnection; the speech lasts 10 s).
# 2. The server does not come back (--reconnect 2): dpc-demo ends by itself with exit status
#    1 and one line "dpc-demo: error: audio device ... not back within 2 s" within 10 s of the
#    kill, the recording and stats written up to the failure.
# Usage: live_reconnect_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$1
src=$2
# shellcheck source=jack_private_server.sh
source "$(dirname "$0")/jack_private_server.sh"
jack_private_setup dpc-reconnect "$src"

# Starts dpc-demo (--reconnect $1, --duration $2) into $work/$3 and waits until it plays,
# then 2 s more, and kills the server.
play_and_kill() {
  local out="$work/$3"
  mkdir -p "$out"
  jack_private_start 256 "$out/jackd.log"
  "$build/apps/dpc-demo" "$src/scenes/shoebox.json" --duration "$2" --rays 256 --threads 1 \
      --reconnect "$1" --record "$out/played.wav" --stats "$out/stats.json" \
      >"$out/demo.log" 2>&1 &
  demo_pid=$!
  jack_private_wait_playing "$out/demo.log"
  sleep 2
  kill -TERM "$JACK_PID"
  wait "$JACK_PID" 2>/dev/null || true
  JACK_PID=""
  jack_private_remove_segments
}

# Waits at most $1 tenths of a second for dpc-demo; sets status to its exit status.
wait_demo() {
  local waited=0
  while kill -0 "$demo_pid" 2>/dev/null && ((waited < $1)); do
    sleep 0.1
    waited=$((waited + 1))
  done
  if kill -0 "$demo_pid" 2>/dev/null; then
    echo "FAIL: dpc-demo still running" 
    exit 1
  fi
  status=0
  wait "$demo_pid" || status=$?
  demo_pid=""
}

# Checks $work/$1's recording and stats: at least $2 s recorded, $3 reconnections, and (if
# $4 is "after") sound from 3.5 to 7 s of the recording.
check_outputs() {
  /usr/bin/python3 - "$work/$1" "$2" "$3" "${4:-}" <<'PY'
import json, os, sys
sys.path.insert(0, os.path.join(os.environ["SRC"], "scripts"))
from plot_render import read_wav
import numpy as np
out, least, reconnections, tail = sys.argv[1], float(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
s = json.load(open(os.path.join(out, "stats.json")))
x, rate = read_wav(os.path.join(out, "played.wav"))
seconds = x.shape[1] / rate
after = np.sqrt(np.mean(x[:, int(3.5 * rate):7 * rate] ** 2)) if seconds >= 7 else 0.0
print(f"stats: {s['callbacks']} callbacks, {s['reconnections']} reconnections; recording "
      f"{seconds:.2f} s, rms from 3.5 to 7 s {after:.2e}")
ok = np.all(np.isfinite(x)) and seconds >= least and s["reconnections"] == reconnections
# The shoebox's speech is at 0.1-0.2 rms in every second of its first 10 (an offline render):
# 1e-2 is 20 dB below any of them, and a silent stretch (no sound after the gap) is 0.
if tail == "after":
    ok = ok and after > 1e-2
if not ok:
    print("FAIL: recording or stats")
    sys.exit(1)
PY
}
export SRC=$src

# 1. The server comes back: 2 s played, 2.5 s without a server, then to the end (14 s).
play_and_kill 8 14 back
sleep 2.5
jack_private_start 256 "$work/back/jackd2.log"
wait_demo 200
tr '\r' '\n' <"$work/back/demo.log" | grep -E '^(dpc-demo|wrote)' || true
[[ $status -eq 0 ]] || { echo "FAIL: exit status $status after the server came back"; exit 1; }
grep -q "^dpc-demo: reopened" "$work/back/demo.log" || { echo "FAIL: no reopened line"; exit 1; }
# More than the 2-3 s before the kill: the seconds after the reconnection were recorded too.
check_outputs back 7 1 after
kill -TERM "$JACK_PID"
wait "$JACK_PID" 2>/dev/null || true
JACK_PID=""
jack_private_remove_segments

# 2. The server stays away: the session gives up 2 s after the failure.
play_and_kill 2 60 gone
killed=$(date +%s.%N)
wait_demo 100
echo "server gone: dpc-demo ended $(echo "$(date +%s.%N) - $killed" | bc) s after the kill"
tr '\r' '\n' <"$work/gone/demo.log" | grep -E '^(dpc-demo|wrote)' || true
[[ $status -eq 1 ]] || { echo "FAIL: exit status $status, expected 1"; exit 1; }
lines=$(tr '\r' '\n' <"$work/gone/demo.log" | grep -c '^dpc-demo: error: audio device.*not back within 2 s' || true)
[[ $lines -eq 1 ]] || { echo "FAIL: $lines error lines saying the device is not back"; exit 1; }
check_outputs gone 1 0
echo "PASS: reconnected when the server came back, ended cleanly when it did not"
