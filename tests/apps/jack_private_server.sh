#!/usr/bin/env bash
# Sourced by the live JACK tests: a JACK server of the test's own (dummy backend) under a fixed
# name, so no other test's server is touched and the registry slot a SIGKILLed server leaves
# behind is reclaimed by the next run of the same test (JACK holds at most 8 server names and
# frees a dead server's slot only when its name registers again).
#   jack_private_init NAME SOURCE_DIR   exports JACK_DEFAULT_SERVER=NAME, no auto-start, and
#                                       clears stale registry slots (scripts/jack-reclaim.sh)
#   jack_private_start PERIOD LOG       starts jackd -r -d dummy -r 48000 -p PERIOD (its output
#                                       to LOG), sets JACK_PID, waits until it answers; exits 1
#                                       with its log when it does not start within 10 s
#   jack_private_remove_segments        removes this server's shared-memory segments and
#                                       semaphores (a SIGKILLed server cannot); never another's
#   jack_private_wait_playing LOG       waits (at most 30 s) for dpc-demo's "playing on" line
#                                       in LOG
#   jack_private_setup NAME SOURCE_DIR  jack_private_init, a scratch folder $work, and an EXIT
#                                       trap that kills the server ($JACK_PID) and the test's
#                                       processes ($demo_pid, the array pids) if still set,
#                                       then removes $work and the server's segments

jack_private_init() {
  export JACK_DEFAULT_SERVER=$1
  export JACK_NO_START_SERVER=1
  "$2/scripts/jack-reclaim.sh"
}

jack_private_start() {
  jackd -n "$JACK_DEFAULT_SERVER" -r -d dummy -r 48000 -p "$1" >"$2" 2>&1 &
  JACK_PID=$!
  for _ in $(seq 1 50); do
    jack_lsp >/dev/null 2>&1 && return 0
    sleep 0.2
  done
  cat "$2"
  echo "FAIL: jackd did not start"
  exit 1
}

jack_private_remove_segments() {
  rm -f /dev/shm/jack_"$JACK_DEFAULT_SERVER"_* /dev/shm/jack_sem.*_"$JACK_DEFAULT_SERVER"_* \
      2>/dev/null || true
}

jack_private_cleanup() {
  local p
  for p in ${demo_pid:-} "${pids[@]}" ${JACK_PID:-}; do
    [[ -n $p ]] && kill -KILL "$p" 2>/dev/null || true
  done
  rm -rf "$work"
  jack_private_remove_segments
}

jack_private_setup() {
  work=$(mktemp -d)
  JACK_PID=""
  demo_pid=""
  pids=()
  trap jack_private_cleanup EXIT
  jack_private_init "$1" "$2"
}

jack_private_wait_playing() {
  for _ in $(seq 1 300); do
    grep -q "^playing on" "$1" && return 0
    sleep 0.1
  done
}
