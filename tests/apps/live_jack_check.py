"""Checks one live JACK session of tests/apps/live_jack_test.sh (see its header for the bounds).

Reads, from the session's folder: stats.json (dpc-demo --stats), jackd.log (the server's log,
which names each client that was not finished when a cycle ended) and ref-before.txt /
ref-after.txt (scripts/jack-reference-client.c's output). Prints what it measured and one line
per failure; exits 1 on any failure.

  live_jack_check.py SESSION_DIR SECONDS
"""
import json
import math
import re
import sys
from pathlib import Path

DEMO = 'dpc-demo'
REFERENCES = ('ref-before', 'ref-after')
# One-sided three standard deviations of a normal variable.
LATE_P_VALUE = 0.00135


def client_xruns(log_text, client):
    """Cycles that ended with the client not finished, or finished after the cycle's end."""
    name = re.escape(client)
    late_end = rf'JackEngine::XRun: client = {name} was not finished'
    finished_after = rf'JackEngine::XRun: client {name} finished after current callback'
    return len(re.findall(late_end, log_text)) + len(re.findall(finished_after, log_text))


def reference_counts(path):
    """(cycles, late callbacks, mean load %) printed by jack-reference-client."""
    text = path.read_text()
    counts = re.search(r'cycles (\d+) xruns \d+ late (\d+)', text)
    load = re.search(r'load mean ([0-9.]+)', text)
    if not counts or not load:
        raise SystemExit(f'FAIL: {path.name}: no counts from the reference client (got {text!r})')
    return int(counts.group(1)), int(counts.group(2)), float(load.group(1))


def poisson_bound(expected):
    """Three standard deviations above a Poisson count's mean."""
    return expected + 3 * math.sqrt(expected + 1)


def late_p_value(demo_late, ref_late, demo_exposure, ref_exposure):
    """The chance that dpc-demo gets at least demo_late of all the late callbacks if it is
    stopped at the references' rate per second inside a callback: given the total n, its count
    is binomial with p = its share of the time spent inside callbacks (the conditional test of
    two Poisson rates, exact for counts as small as 0)."""
    n = demo_late + ref_late
    p = demo_exposure / max(demo_exposure + ref_exposure, 1e-12)
    return sum(math.comb(n, k) * p**k * (1 - p)**(n - k) for k in range(demo_late, n + 1))


def real_time_failures(s, log_text, refs):
    """dpc-demo's xruns and late callbacks against the references' in the same graph."""
    fails = []
    callbacks = s['callbacks']
    demo_xruns = client_xruns(log_text, DEMO)
    rate = max(client_xruns(log_text, name) / max(cycles, 1)
               for name, (cycles, _, _) in refs.items())
    xrun_bound = poisson_bound(rate * callbacks) + callbacks / 1000
    print(f'{DEMO}: {demo_xruns} xruns of its own in {callbacks} callbacks; references: '
          + ', '.join(f'{n} {client_xruns(log_text, n)} in {c}' for n, (c, _, _) in refs.items())
          + f'; driver wake-ups late {log_text.count("Driver::Process XRun")}'
          + f' (bound for {DEMO} {xrun_bound:.1f})')
    if demo_xruns > xrun_bound:
        fails.append(f'{demo_xruns} xruns of dpc-demo in {callbacks} callbacks (references at '
                     f'most {rate * 1000:.2f} per 1000: bound {xrun_bound:.1f})')
    demo_load = s['callback_load_percent']['mean']
    demo_exposure = demo_load * callbacks
    ref_exposure = sum(load * cycles for cycles, _, load in refs.values())
    ref_late = sum(late for _, late, _ in refs.values())
    p_value = late_p_value(s['late_callbacks'], ref_late, demo_exposure, ref_exposure)
    print(f'late callbacks: {DEMO} {s["late_callbacks"]} (mean load {demo_load:.2f} %); references '
          + ', '.join(f'{n} {late} (mean load {load:.2f} %)' for n, (_, late, load) in refs.items())
          + f'; chance of as many at the references\' rate {p_value:.2g}')
    if p_value < LATE_P_VALUE:
        fails.append(f"{s['late_callbacks']} callbacks overran their period against "
                     f'{ref_late} of the references (chance {p_value:.2g} < {LATE_P_VALUE})')
    return fails


def report(s, seconds):
    sched = s['callback_scheduling']
    lat = s['motion_to_sound_latency_ms']
    load = s['callback_load_percent']
    print(f"callback scheduling: {sched['policy']} priority {sched['priority']}")
    print(f"callbacks {s['callbacks']}, xruns (the server's, any client) {s['xruns']}, late "
          f"callbacks {s['late_callbacks']}, worker deadline misses {s['worker_deadline_misses']}")
    print(f"callback load %: mean {load['mean']:.1f} median {load['median']:.1f} p99 "
          f"{load['p99']:.1f} p99.9 {load['p99_9']:.1f} max {load['max']:.1f}")
    for late in s['late_callbacks_first']:
        print(f"late callback at {late['at_s']:.3f} s: {late['ms']:.2f} ms")
    print(f"IRs applied {s['irs_applied']} in {seconds:.0f} s; motion-to-sound latency ms: median "
          f"{lat['median']:.1f} p95 {lat['p95']:.1f} p99 {lat['p99']:.1f} max {lat['max']:.1f}")


def main():
    session = Path(sys.argv[1])
    seconds = float(sys.argv[2])
    s = json.loads((session / 'stats.json').read_text())
    log_path = session / 'jackd.log'
    log_text = log_path.read_text() if log_path.exists() else ''
    if 'JACK server starting' not in log_text:
        raise SystemExit('FAIL: jackd.log: not the log of the server this session started')
    refs = {name: reference_counts(session / f'{name}.txt') for name in REFERENCES}
    report(s, seconds)
    fails = []
    # hall.json runs 15 frames/s; a loaded 2-core machine may halve the propagation rate.
    if s['irs_applied'] < 7.5 * seconds * 0.9:
        fails.append(f"only {s['irs_applied']} IRs applied (need >= {7.5 * seconds * 0.9:.0f})")
    if s['nan_blocks'] != 0:
        fails.append(f"{s['nan_blocks']} blocks had NaN/inf")
    if s['worker_deadline_misses'] != 0:
        fails.append(f"{s['worker_deadline_misses']} worker deadline misses")
    if s['callback_scheduling']['real_time']:
        fails += real_time_failures(s, log_text, refs)
    else:
        print(f"xruns not asserted: the callback ran {s['callback_scheduling']['policy']} "
              '(no real-time priority here)')
    for f in fails:
        print('FAIL: ' + f)
    sys.exit(1 if fails else 0)


if __name__ == '__main__':
    main()
