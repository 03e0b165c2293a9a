#!/usr/bin/env bash
# Headless proof of live playback: a JACK server on the dummy backend (no sound card) at 128
# frames, with real-time priority (jackd -R) where the machine grants SCHED_FIFO, and dpc-demo
# playing the hall for 60 s with the listener walking, recording what it played and writing
# --stats. Asserts: exit 0; IRs applied at no less than half the frame rate (the tracer shares
# the machine with the test runner); recording non-silent and finite; no worker deadline miss;
# and, when the audio callback ran SCHED_FIFO, that the engine adds no xruns and no overlong
# callbacks to what the machine itself causes:
#   first, for the same time, a do-nothing JACK client runs beside an offline render of the
#   same scene with the same rays and threads (scripts/jack-xrun-baseline.sh): its xruns X0 and
#   callbacks longer than the period L0 are the machine's (on a VM, the host descheduling a
#   virtual CPU; measured 0 to 115 a minute on the same 2-core machine on different days);
#   then dpc-demo plays live, and its xruns must be at most one per 1000 callbacks (target 0)
#   plus X0 + 3 sqrt(X0 + 1), its late callbacks at most L0 + 3 sqrt(L0 + 1) (Poisson counts:
#   three standard deviations of the baseline's count). The machine's rate drifts within
#   minutes (19 xruns in the minute before a live run that met 57 with 1 late callback), so
#   the baseline is measured before and after the live run and the larger count is used.
#   A callback is late when the machine stops it for longer than a period while it runs, so
#   the chance scales with the time spent inside callbacks: a do-nothing client is almost
#   never inside one (CI once saw late 0 twice around a live run with 8). The baseline after
#   the live run therefore does constant work equal to the live callback's mean load
#   (WORK_PERCENT), so both clients are exposed to the machine for the same time.
# Without real-time scheduling xruns are reported, not asserted (a preemptible callback on a
# loaded machine misses deadlines that are not dpc's to keep). Motion-to-sound latency is
# reported (it is a timing of the shared machine, not a property of the code).
# Usage: live_jack_test.sh BUILD_DIR SOURCE_DIR [SECONDS]
set -euo pipefail
build=$1
src=$2
seconds=${3:-60}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
log="$work/log.txt"
measure_baseline() {  # $1: the client's constant work, % of the period
  WORK_PERCENT=$1 JACK_PERIOD=128 "$src/scripts/jack-xrun-baseline.sh" "$seconds" 0 -- \
      "$build/apps/dpc-demo" "$src/scenes/hall.json" --offline "$work/load.wav" \
      --duration "$seconds" --rays 1024 --threads 1 --quiet 2>/dev/null | tail -n 1
  rm -f "$work/load.wav"
}
baseline=$(measure_baseline 0)
echo "machine baseline (do-nothing client beside an offline render): $baseline"
if ! JACK_PERIOD=128 "$src/scripts/jack-headless.sh" "$build/apps/dpc-demo" \
    "$src/scenes/hall.json" --duration "$seconds" --block-size 128 --rays 1024 --threads 1 \
    --record "$work/played.wav" --stats "$work/stats.json" >"$log" 2>&1; then
  cat "$log"
  echo "FAIL: dpc-demo did not exit 0"
  exit 1
fi
grep -E '^(wrote|live:|audio callback:)' "$log" || true
work_percent=$(/usr/bin/python3 -c 'import json, sys
print("%.2f" % json.load(open(sys.argv[1]))["callback_load_percent"]["mean"])' "$work/stats.json")
baseline_after=$(measure_baseline "$work_percent")
echo "machine baseline after the live run (client working ${work_percent} % of each period): $baseline_after"
/usr/bin/python3 - "$work/stats.json" "$seconds" "$baseline" "$baseline_after" <<'PY'
import json, math, re, sys
s = json.load(open(sys.argv[1]))
seconds = float(sys.argv[2])
bases = []
for text in sys.argv[3:5]:
    m = re.fullmatch(r'cycles (\d+) xruns (\d+) late (\d+)', text.strip())
    if not m:
        print(f'FAIL: no machine baseline (got {text!r})')
        sys.exit(1)
    bases.append(tuple(map(int, m.groups())))
# The machine at its noisier: the baseline with more xruns; late callbacks likewise.
base_cycles, base_xruns, _ = max(bases, key=lambda b: b[1])
base_late = max(b[2] for b in bases)
fails = []
sched = s['callback_scheduling']
lat = s['motion_to_sound_latency_ms']
load = s['callback_load_percent']
print(f"callback scheduling: {sched['policy']} priority {sched['priority']}")
print(f"callbacks {s['callbacks']}, xruns {s['xruns']}, late callbacks {s['late_callbacks']}, "
      f"worker deadline misses {s['worker_deadline_misses']}")
print(f"callback load %: mean {load['mean']:.1f} median {load['median']:.1f} p99 {load['p99']:.1f} "
      f"p99.9 {load['p99_9']:.1f} max {load['max']:.1f}")
for late in s['late_callbacks_first']:
    print(f"late callback at {late['at_s']:.3f} s: {late['ms']:.2f} ms")
print(f"IRs applied {s['irs_applied']} in {seconds:.0f} s; motion-to-sound latency ms: median "
      f"{lat['median']:.1f} p95 {lat['p95']:.1f} p99 {lat['p99']:.1f} max {lat['max']:.1f}")
# hall.json runs 15 frames/s; a loaded 2-core machine may halve the propagation rate.
if s['irs_applied'] < 7.5 * seconds * 0.9:
    fails.append(f"only {s['irs_applied']} IRs applied (need >= {7.5 * seconds * 0.9:.0f})")
if s['nan_blocks'] != 0:
    fails.append(f"{s['nan_blocks']} blocks had NaN/inf")
if s['worker_deadline_misses'] != 0:
    fails.append(f"{s['worker_deadline_misses']} worker deadline misses")
if sched['real_time']:
    # dpc's own deadline: no callback may take longer than the audio it produces, beyond what
    # the machine does to a callback that works as long on average.
    late_bound = base_late + 3 * math.sqrt(base_late + 1)
    if s['late_callbacks'] > late_bound:
        fails.append(f"{s['late_callbacks']} callbacks overran their period (machine baseline "
                     f"{base_late}: bound {late_bound:.1f})")
    # JACK's count also holds the dummy driver's own late wake-ups: at most one per 1000
    # callbacks (target 0) beyond the machine's own.
    xrun_bound = s['callbacks'] / 1000 + base_xruns + 3 * math.sqrt(base_xruns + 1)
    if s['xruns'] > xrun_bound:
        fails.append(f"{s['xruns']} xruns in {s['callbacks']} callbacks with a real-time callback "
                     f"(machine baseline {base_xruns} in {base_cycles}: bound {xrun_bound:.1f})")
else:
    print(f"xruns not asserted: the callback ran {sched['policy']} (no real-time priority here)")
for f in fails:
    print('FAIL: ' + f)
sys.exit(1 if fails else 0)
PY
/usr/bin/python3 "$src/scripts/wavcheck.py" "$work/played.wav" || { echo "FAIL: recording"; exit 1; }
echo "PASS: live playback on JACK (dummy, 128 frames)"
