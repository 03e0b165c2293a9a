#!/usr/bin/python3
"""Plots `dpc-bench dynamic` JSON into docs/images/dynamic-step.png (door step response per
estimator and tau, with the tau bound) and prints the t90 table (markdown) on stdout; plots
`dpc-bench listeners` JSON (--listeners, one file per scene) into
docs/images/dynamic-listeners.png (frame CPU time for 1, 2, 4, 8 listeners traced in one pass,
relative to one listener, with the 1.5x target) and prints its table.

Usage: /usr/bin/python3 scripts/plot_dynamic.py [--in docs/data/dynamic.json] [--out docs/images]
           [--listeners docs/data/listeners-hall.json docs/data/listeners-two_rooms.json]
           [--moving-source docs/data/dynamic-moving-source.json]
--moving-source plots `dpc-bench dynamic --parts moving_source` into
docs/images/dynamic-moving-source.png (per-frame relative error, walking vs static source).
Needs matplotlib (Debian: python3-matplotlib; /usr/bin/python3).
"""
import argparse
import json
import os

import matplotlib
matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402

ap = argparse.ArgumentParser()
ap.add_argument('--in', dest='inp', default='docs/data/dynamic.json')
ap.add_argument('--out', default='docs/images')
ap.add_argument('--listeners', nargs='*', default=[])
ap.add_argument('--moving-source', dest='moving', default=None)
a = ap.parse_args()
d = json.load(open(a.inp))
steps = d['step_response']
if not steps:
    raise SystemExit(f"{a.inp}: no step_response (run dpc-bench dynamic with the step part)")
taus = sorted({s['tau'] for s in steps})
names = ['window', 'ema', 'ema_matched', 'seed']
fig, axes = plt.subplots(1, len(taus), figsize=(4 * len(taus), 3.6), sharey=True)
for ax, tau in zip(axes, taus):
    for s in steps:
        if s['tau'] != tau:
            continue
        T, lvl = s['frame_period'], s['open_level']
        y = [v / lvl for v in s['shut'] + s['reopen']]
        t = [k * T for k in range(len(y))]
        ax.plot(t, y, label=s['weighting'], lw=1.2)
        half = len(s['shut']) * T
    for t0 in (0.0, half):
        ax.axvspan(t0, t0 + tau, color='0.9')
        ax.axvline(t0 + tau, color='k', ls=':', lw=0.8)
    ax.axhline(0.1, color='r', lw=0.5)
    ax.axhline(0.9, color='r', lw=0.5)
    ax.set_title(f'tau = {tau} s (shaded: within tau)')
    ax.set_xlabel('time since the door shut (s); reopened at the middle')
axes[0].set_ylabel('late energy at the listener / open level (500 Hz)')
axes[0].legend(fontsize=8)
fig.tight_layout()
os.makedirs(a.out, exist_ok=True)
fig.savefig(os.path.join(a.out, 'dynamic-step.png'), dpi=90)

print('| weighting | tau (s) | time constant (s) | t90 shut (s) | t90 open (s) | within tau | readout sd / mean |')
print('|---|---|---|---|---|---|---|')
for n in names:
    for s in steps:
        if s['weighting'] != n:
            continue
        ok = s['t90_shut'] <= s['tau'] and s['t90_open'] <= s['tau']
        print(f"| {n} | {s['tau']} | {s['time_constant']:.3g} | {s['t90_shut']:.2f} | "
              f"{s['t90_open']:.2f} | {'yes' if ok else 'no'} | {s['open_relative_sd']:.3f} |")
print()
print('| moving objects | triangles | moving CPU ms/frame | static CPU ms/frame | ratio |')
print('|---|---|---|---|---|')
for o in d['moving_objects']:
    print(f"| {o['objects']} | {o['triangles']} | {o['moving_cpu_ms_per_frame']:.1f} | "
          f"{o['static_cpu_ms_per_frame']:.1f} | {o['ratio']:.2f} |")

if a.listeners:
    fig, ax = plt.subplots(figsize=(5.5, 3.8))
    print()
    print('| scene | listeners | pass CPU ms/frame | ratio to 1 | IR prep. all listeners ms | '
          'Embree segments/frame | sphere hits/frame |')
    print('|---|---|---|---|---|---|---|')
    for path in a.listeners:
        ld = json.load(open(path))
        rows = ld['listeners']
        name = os.path.splitext(os.path.basename(ld['scene']))[0]
        n = [r['listeners'] for r in rows]
        ax.plot(n, [r['pass_ratio_to_one'] for r in rows], 'o-',
                label=f"{name}: pass (trace + caches)")
        base = rows[0]['pass_cpu_ms_per_frame']
        ax.plot(n, [(r['pass_cpu_ms_per_frame'] + r['prepare_all_cpu_ms_per_frame']) / base
                    for r in rows], 's--', label=f"{name}: + IRs of every listener")
        for r in rows:
            print(f"| {name} | {r['listeners']} | {r['pass_cpu_ms_per_frame']:.1f} | "
                  f"{r['pass_ratio_to_one']:.2f} | {r['prepare_all_cpu_ms_per_frame']:.1f} | "
                  f"{r['segments_per_frame']:.0f} | {r['sphere_hits_per_frame']:.0f} |")
    ax.axhline(1.5, color='r', lw=0.8, ls=':', label='target 1.5x')
    ax.plot([1, 8], [1, 8], color='0.6', lw=0.8, label='one pass per listener')
    ax.set_xscale('log', base=2)
    ax.set_xticks([1, 2, 4, 8])
    ax.set_xticklabels(['1', '2', '4', '8'])
    ax.set_ylim(0.8, 3.0)
    ax.set_xlabel('listeners traced in one pass')
    ax.set_ylabel('frame CPU time / one listener')
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(a.out, 'dynamic-listeners.png'), dpi=90)

if a.moving:
    m = json.load(open(a.moving))['moving_source']
    fig, ax = plt.subplots(figsize=(6, 3.6))
    T = m['frame_period']
    print()
    print('| source | estimator | mean relative error | mean flicker |')
    print('|---|---|---|---|')
    for c in m['cases']:
        y = c['error_per_frame']
        ax.plot([k * T for k in range(len(y))], y,
                ls='-' if c['source'] == 'walking' else '--',
                label=f"{c['estimator']}, {c['source']} source")
        print(f"| {c['source']} | {c['estimator']} | {c['mean_error']:.3f} | "
              f"{c['mean_flicker']:.3f} |")
    ax.axvspan(0, m['warmup_frames'] * T, color='0.9', label='warm-up (tau)')
    ax.set_xlabel(f"time (s); source walks at {m['speed_m_per_s']} m/s")
    ax.set_ylabel('relative RMS error of the energy response')
    ax.set_title(f"{m['scene']}; tau = {m['tau']} s", fontsize=8)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(a.out, 'dynamic-moving-source.png'), dpi=90)
