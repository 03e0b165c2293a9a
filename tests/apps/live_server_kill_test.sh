#!/usr/bin/env bash
# A live session survives its audio server: dpc-demo plays the shoebox on a JACK server of its
# own (dummy backend, fixed name: tests/apps/jack_private_server.sh), recording (--record) and
# writing --stats, and the server is killed while it plays, once with SIGTERM
# and once with SIGKILL. Asserts, each run: dpc-demo ends by itself with exit status 1 and
# one line "dpc-demo: error: audio device ...", well before its --duration (within 10 s of
# the kill: no hang; the time taken is printed, the design target being 2 s); the recording
# exists, is finite and not silent and holds at least the second played before the kill; the
# stats file is complete JSON with the callbacks counted.
# Usage: live_server_kill_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$1
src=$2
# shellcheck source=jack_private_server.sh
source "$(dirname "$0")/jack_private_server.sh"
jack_private_setup dpc-server-kill "$src"

run_once() {  # $1: the signal that kills the server
  local sig=$1 out="$work/$1"
  mkdir -p "$out"
  jack_private_start 256 "$out/jackd.log"
  "$build/apps/dpc-demo" "$src/scenes/shoebox.json" --duration 60 --rays 256 --threads 1 \
      --record "$out/played.wav" --stats "$out/stats.json" >"$out/demo.log" 2>&1 &
  demo_pid=$!
  # Until it plays (its first status line), then a little more.
  jack_private_wait_playing "$out/demo.log"
  sleep 2
  kill -"$sig" "$JACK_PID"
  local killed
  killed=$(date +%s.%N)
  wait "$JACK_PID" 2>/dev/null || true
  JACK_PID=""
  jack_private_remove_segments
  local waited=0
  while kill -0 "$demo_pid" 2>/dev/null && ((waited < 100)); do
    sleep 0.1
    waited=$((waited + 1))
  done
  if kill -0 "$demo_pid" 2>/dev/null; then
    cat "$out/demo.log"
    echo "FAIL ($sig): dpc-demo still running 10 s after the server was killed"
    exit 1
  fi
  local status=0
  wait "$demo_pid" || status=$?
  demo_pid=""
  local ended
  ended=$(date +%s.%N)
  tr '\r' '\n' <"$out/demo.log" | grep -E '^(dpc-demo|wrote|note)' || true
  echo "server killed with SIG$sig: dpc-demo ended $(echo "$ended - $killed" | bc) s later," \
       "exit status $status"
  [[ $status -eq 1 ]] || { echo "FAIL ($sig): exit status $status, expected 1"; exit 1; }
  local lines
  lines=$(tr '\r' '\n' <"$out/demo.log" | grep -c '^dpc-demo: error: audio device' || true)
  [[ $lines -eq 1 ]] || { echo "FAIL ($sig): $lines error lines about the device"; exit 1; }
  /usr/bin/python3 "$src/scripts/wavcheck.py" "$out/played.wav" ||
      { echo "FAIL ($sig): recording"; exit 1; }
  /usr/bin/python3 - "$out/stats.json" "$out/played.wav" "$sig" <<'PY'
import json, os, sys
s = json.load(open(sys.argv[1]))
size = os.path.getsize(sys.argv[2])
# 2 channels of float32 at 48 kHz: a second played is 384,000 bytes.
seconds = (size - 44) / 384000.0
print(f"stats: {s['callbacks']} callbacks; recording {seconds:.2f} s")
if s["callbacks"] <= 0 or seconds < 1.0 or seconds > 30.0:
    print(f"FAIL ({sys.argv[3]}): callbacks {s['callbacks']}, recording {seconds:.2f} s")
    sys.exit(1)
PY
}

run_once TERM
run_once KILL
echo "PASS: the session ended cleanly both times, recording and stats complete"
