#!/usr/bin/python3
"""Plots the dpc-bench JSON files written by scripts/bench_sweep.sh (out/bench/) into
docs/images/perf-*.png and prints the issue-4 target table (markdown) on stdout.

Usage: /usr/bin/python3 scripts/plot_bench.py [--in DIR ...] [--out docs/images]
  --in DIR  folder with the JSON files and sweep-log.tsv (default out/bench). Given several
            times (e.g. several passes of the sweep on a shared machine, newest first), each
            file is taken from the first folder whose run had the machine to itself (other
            processes <= 0.25 core, sweep-log.tsv), else from the least disturbed run.

Files read (missing ones are skipped with a note on stderr):
  prop-{shoebox,hall}-rays-N.json, -rays-4096-noroulette.json, -rays-4096-t1.json
  prop-hall-order-D.json, prop-hall-tri-kK-tT.json, prop-hall-cache.json
  noise-shoebox-static-rays-N.json, noise-shoebox-walk.json, live-*.json
  sweep-log.tsv (machine load during each run)
Needs numpy and matplotlib (Debian: python3-numpy python3-matplotlib; /usr/bin/python3).
"""
import argparse
import csv
import glob
import json
import math
import os
import re
import sys

import matplotlib
matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.ticker  # noqa: E402
import numpy as np  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
ap.add_argument('--in', dest='inp', action='append')
ap.add_argument('--out', default=os.path.join(ROOT, 'docs', 'images'))
args = ap.parse_args()
args.inp = args.inp or [os.path.join(ROOT, 'out', 'bench')]
os.makedirs(args.out, exist_ok=True)

COLORS = {'shoebox': 'tab:blue', 'hall': 'tab:red', 'dpc_ema': 'tab:green',
          'dpc_seed': 'tab:purple', 'pt': 'tab:gray'}
plt.rcParams.update({'font.size': 10, 'axes.grid': True, 'grid.alpha': 0.3,
                     'figure.dpi': 110, 'savefig.bbox': 'tight'})


LOGS = {}  # folder -> file -> log row of its last run there
for d in args.inp:
    LOGS[d] = {}
    log_path = os.path.join(d, 'sweep-log.tsv')
    if os.path.exists(log_path):
        with open(log_path) as f:
            for row in csv.DictReader(f, delimiter='\t'):
                LOGS[d][row['file']] = row  # the last run of a file wins
LOADS = {}  # file -> log row of the run used
BUSY_CORES = 0.25  # other processes' CPU use above which a run counts as disturbed


def other_cpu(d, name):
    r = LOGS[d].get(name)
    return float(r['other_cpu_cores']) if r else math.inf


def load(name):
    dirs = [d for d in args.inp if os.path.exists(os.path.join(d, name))]
    if not dirs:
        print(f'plot_bench: missing {name}', file=sys.stderr)
        return None
    # The first folder whose run had the machine to itself; else the least disturbed run.
    quiet = [d for d in dirs if other_cpu(d, name) <= BUSY_CORES]
    d = quiet[0] if quiet else min(dirs, key=lambda d: other_cpu(d, name))
    if name in LOGS[d]:
        LOADS[name] = LOGS[d][name]
    with open(os.path.join(d, name)) as f:
        return json.load(f)


def busy(name):
    """True if other processes used more than BUSY_CORES during the run used for name."""
    r = LOADS.get(name)
    return r is not None and float(r['other_cpu_cores']) > BUSY_CORES


def mark_busy(ax, points):
    """Rings the (x, y, file) points whose run shared the machine with other work."""
    b = [(x, y) for x, y, n in points if busy(n)]
    if b:
        ax.plot([p[0] for p in b], [p[1] for p in b], 'o', ms=13, mfc='none', mec='k', mew=0.8,
                label=f'run shared the CPU (others > {BUSY_CORES:g} core)')


def load_note(name):
    r = LOADS.get(name)
    if not r:
        return 'load not recorded'
    note = f"{float(r['other_cpu_cores']):.2f} cores ({r['started'][11:16]})"
    if name.startswith('noise'):
        note += ', does not affect noise results'
    return note


def frame_ms(j, key='median'):
    return j['full_frame']['frame_ms'][key]


def bare_ms(j):
    """Time bare Embree needs for the full frame's segments: the yardstick in ms/frame."""
    return 1e3 * j['full_frame']['segments_per_frame'] / j['bare_embree']['segments_per_second']


def save(fig, name):
    path = os.path.join(args.out, name)
    fig.savefig(path)
    plt.close(fig)
    print(f'plot_bench: wrote {path}', file=sys.stderr)


RAYS = [512, 1024, 2048, 4096, 8192, 16384]
TARGET_MS = {'shoebox': 50.0, 'hall': 100.0}

# --- frame time vs rays ------------------------------------------------------------------
fig, ax = plt.subplots(figsize=(7.5, 5))
busy_pts = []
for scene in ('shoebox', 'hall'):
    pts = [(r, load(f'prop-{scene}-rays-{r}.json')) for r in RAYS]
    pts = [(r, j) for r, j in pts if j]
    if not pts:
        continue
    c = COLORS[scene]
    r = np.array([p[0] for p in pts])
    med = np.array([frame_ms(p[1]) for p in pts])
    p95 = np.array([frame_ms(p[1], 'p95') for p in pts])
    ax.errorbar(r, med, yerr=[np.zeros_like(med), p95 - med], color=c, marker='o', capsize=3,
                label=f'{scene}: full frame (median, bar to p95)')
    ax.plot(r, [bare_ms(p[1]) for p in pts], color=c, ls=':', marker='.',
            label=f'{scene}: bare Embree, same segments')
    nr = load(f'prop-{scene}-rays-4096-noroulette.json')
    if nr:
        ax.plot([4096], [frame_ms(nr)], color=c, marker='s', ls='none', mfc='none', ms=9,
                label=f'{scene}: 4096, no roulette')
    t1 = load(f'prop-{scene}-rays-4096-t1.json')
    if t1:
        ax.plot([4096], [frame_ms(t1)], color=c, marker='^', ls='none', mfc='none', ms=9,
                label=f'{scene}: 4096, 1 thread')
    busy_pts += [(r_, frame_ms(j_), f'prop-{scene}-rays-{r_}.json') for r_, j_ in pts]
    if nr:
        busy_pts.append((4096, frame_ms(nr), f'prop-{scene}-rays-4096-noroulette.json'))
    if t1:
        busy_pts.append((4096, frame_ms(t1), f'prop-{scene}-rays-4096-t1.json'))
    ax.axhline(TARGET_MS[scene], color=c, ls='--', lw=1)
    ax.text(520, TARGET_MS[scene] * 1.06, f'{scene} target {TARGET_MS[scene]:g} ms @ 4096',
            color=c, fontsize=8)
ax.set_xscale('log', base=2)
ax.set_yscale('log')
ax.set_xticks(RAYS)
ax.set_xticklabels([str(r) for r in RAYS])
ax.set_xlabel('rays per frame (one source)')
ax.set_ylabel('frame time, ms')
mark_busy(ax, busy_pts)
ax.set_title('Frame time vs rays: max order 200, 2 threads, roulette on')
ax.legend(fontsize=7, loc='lower right')
save(fig, 'perf-frame-vs-rays.png')

# --- frame time vs max order -------------------------------------------------------------
ORDERS = [10, 25, 50, 100, 200, 400]
pts = [(d, load(f'prop-hall-order-{d}.json')) for d in ORDERS]
pts = [(d, j) for d, j in pts if j]
if pts:
    fig, ax = plt.subplots(figsize=(7, 4.3))
    d = [p[0] for p in pts]
    ax.plot(d, [frame_ms(p[1]) for p in pts], color=COLORS['hall'], marker='o',
            label='hall: full frame (median)')
    ax.plot(d, [bare_ms(p[1]) for p in pts], color=COLORS['hall'], marker='.', ls=':',
            label='bare Embree, same segments')
    ax.plot(d, [p[1]['full_frame']['estimator_ms']['median'] for p in pts], color='tab:orange',
            marker='x', label='of which DPC estimator (median)')
    mark_busy(ax, [(d_, frame_ms(j_), f'prop-hall-order-{d_}.json') for d_, j_ in pts])
    ax.axhline(100, color='k', ls='--', lw=1)
    ax.text(10, 110, 'hall target 100 ms (order 200)', fontsize=8)
    ax.set_xscale('log')
    ax.set_yscale('log')
    ax.set_xticks(ORDERS)
    ax.set_xticklabels([str(o) for o in ORDERS])
    ax.set_xlabel('max reflection order (every ray traced to it: --no-roulette)')
    ax.set_ylabel('frame time, ms')
    ax.set_title('Frame time vs max order: hall, 4096 rays, 2 threads')
    ax.legend(fontsize=8, loc='center right')
    save(fig, 'perf-frame-vs-order.png')

# --- frame time vs triangles -------------------------------------------------------------
fig, ax = plt.subplots(figsize=(7, 4.5))
any_tri = False
tri_busy = []
for t, c in ((1, 'tab:blue'), (2, 'tab:red')):
    named = [(f'prop-hall-tri-k{k}-t{t}.json', load(f'prop-hall-tri-k{k}-t{t}.json'))
             for k in range(4)]
    named = [(nm, j) for nm, j in named if j]
    if not named:
        continue
    pts = [j for _, j in named]
    any_tri = True
    n = [j['triangles'] for j in pts]
    tri_busy += [(j['triangles'], frame_ms(j), nm) for nm, j in named]
    ax.plot(n, [frame_ms(j) for j in pts], color=c, marker='o',
            label=f'{t} thread{"s" if t > 1 else ""}: full frame (median)')
    ax.plot(n, [bare_ms(j) for j in pts], color=c, marker='.', ls=':',
            label=f'{t} thread{"s" if t > 1 else ""}: bare Embree, same segments')
if any_tri:
    mark_busy(ax, tri_busy)
    ax.axhline(100, color='k', ls='--', lw=1)
    ax.text(2.2e5, 92, 'hall target 100 ms', fontsize=8)
    ax.axhline(50, color='gray', ls='--', lw=1)
    ax.text(1.7e4, 52, 'shoebox target 50 ms', fontsize=8, color='gray')
    ax.set_xscale('log')
    ax.set_yscale('log')
    yt = [50, 100, 200, 300, 500, 700]
    ax.set_yticks(yt)
    ax.set_yticklabels([str(y) for y in yt])
    ax.yaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    ax.set_xlabel('triangles (hall, each triangle split into 4^K, K = 0..3)')
    ax.set_ylabel('frame time, ms')
    ax.set_title('Frame time vs triangle count: hall, 4096 rays, order 200, no roulette')
    ax.legend(fontsize=8, loc='lower right')
    save(fig, 'perf-frame-vs-triangles.png')
else:
    plt.close(fig)

# --- error vs frames ---------------------------------------------------------------------
static4096 = load('noise-shoebox-static-rays-4096.json')
walk = load('noise-shoebox-walk.json')
runs = [(static4096, 'static listener'), (walk, 'walking 1.4 m/s')]
runs = [(j, t) for j, t in runs if j]
if runs:
    fig, axes = plt.subplots(1, len(runs), figsize=(11, 4.4), sharey=True, squeeze=False)
    for ax, (j, title) in zip(axes[0], runs):
        est = j['estimators']
        warm = j['warmup_frames']
        for key, label in (('dpc_ema', 'DPC, EMA weighting (default)'),
                           ('dpc_seed', 'DPC, thesis (seed) weighting')):
            e = est[key]['error_per_frame']
            ax.plot(np.arange(1, len(e) + 1), e, color=COLORS[key], label=label)
        pt = j['path_tracing']['1x']['error_per_frame']
        ax.plot(np.arange(1, len(pt) + 1), pt, color=COLORS['pt'], lw=0.8,
                label='plain path tracing (every frame independent)')
        ax.axhline(np.mean(pt), color=COLORS['pt'], ls='--', lw=0.8)
        ax.axhline(j['reference']['own_relative_error'], color='k', ls=':', lw=1,
                   label=f"reference's own error ({j['reference']['rays']:.3g} rays)")
        ax.axvline(warm + 0.5, color='k', lw=0.6, alpha=0.5)
        ax.text(warm + 1, 0.006, 'measured frames ->', fontsize=8)
        ax.axhline(0.005, color='tab:orange', ls='--', lw=1)
        ax.text(1, 0.0053, 'issue target 0.5 % after 20 frames', fontsize=8, color='tab:orange')
        ax.set_yscale('log')
        ax.set_ylim(0.004, 4)
        ax.set_xlabel(f"frame since the cache started empty ({j['frame_rate']:g} frames/s)")
        ax.set_title(f"shoebox, {title}\n{j['rays_per_frame']} rays/frame, tau = {j['tau_s']:g} s")
        ax.legend(fontsize=7, loc='upper right', bbox_to_anchor=(0.995, 0.79))
    axes[0][0].set_ylabel('relative L2 error of the frame (8 bands x 10 ms bins)')
    save(fig, 'perf-error-vs-frames.png')

# --- error vs rays -----------------------------------------------------------------------
static = [(r, load(f'noise-shoebox-static-rays-{r}.json')) for r in (1024, 2048, 4096, 8192)]
static = [(r, j) for r, j in static if j]
fit = None
if static:
    fig, ax = plt.subplots(figsize=(7.5, 5))
    pt_r, pt_e = [], []
    for r, j in static:
        for k, m in j['path_tracing'].items():
            pt_r.append(r * int(k.rstrip('x')))
            pt_e.append(m['error_corrected_for_reference'])
    ax.plot(pt_r, pt_e, 'o', color=COLORS['pt'], mfc='none',
            label='plain path tracing (static; all runs)')
    lr, le = np.log(pt_r), np.log(pt_e)
    slope, icpt = np.polyfit(lr, le, 1)
    fit = (slope, icpt)
    dr = [r for r, _ in static]
    de = [j['estimators']['dpc_ema']['error_corrected_for_reference'] for _, j in static]
    x_hi = max(max(pt_r), max(math.exp((math.log(e) - icpt) / slope) for e in de))
    xs = np.geomspace(min(pt_r), x_hi, 50)
    ax.plot(xs, np.exp(icpt) * xs ** slope, color=COLORS['pt'], lw=1,
            label=f'fit: error ~ rays^{slope:.2f}')
    ax.plot(dr, de, 's-', color=COLORS['dpc_ema'], label='DPC, EMA (static), tau = 1 s')
    for r, e in zip(dr, de):
        eq = math.exp((math.log(e) - icpt) / slope)  # PT rays with the same error (fit)
        ratio = eq / r
        ax.annotate('', xy=(eq, e), xytext=(r, e),
                    arrowprops=dict(arrowstyle='->', color=COLORS['dpc_ema'], lw=0.8))
        ax.text(math.sqrt(r * eq), e * 1.05, f'{ratio:.0f}x', ha='center', fontsize=8,
                color=COLORS['dpc_ema'])
    if walk:
        wr = walk['rays_per_frame']
        ax.plot([wr * int(k.rstrip('x')) for k in walk['path_tracing']],
                [m['error_corrected_for_reference'] for m in walk['path_tracing'].values()],
                'v', color='tab:brown', mfc='none', label='path tracing, walking 1.4 m/s')
        we = walk['estimators']['dpc_ema']['error_corrected_for_reference']
        ax.plot([wr], [we], 'v', color='tab:brown', ms=9,
                label=f"DPC walking: equal-noise ratio {walk['equal_noise_ray_ratio']['dpc_ema']:.1f}x")
    ax.set_xscale('log', base=2)
    ax.set_yscale('log')
    ax.set_xlim(min(dr) / 1.3, x_hi * 1.3)
    yt = [0.01, 0.02, 0.03, 0.05, 0.1, 0.2, 0.3]
    ax.set_yticks(yt)
    ax.set_yticklabels([f'{100 * y:g} %' for y in yt])
    ax.yaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    ax.set_xlabel('rays per frame')
    ax.set_ylabel('relative L2 error per frame, corrected for the reference')
    ax.set_title('Error vs rays, shoebox: DPC vs plain path tracing\n'
                 '(arrows: path-tracing rays for the same error, from the fit)')
    ax.legend(fontsize=8, loc='upper right')
    save(fig, 'perf-error-vs-rays.png')

# --- target table (markdown, stdout) ------------------------------------------------------
rows = []


def row(target, measured, ok, src):
    rows.append((target, measured, 'yes' if ok else ('**no**' if ok is not None else 'n/a'),
                 src, load_note(src) if src.endswith('.json') else ''))


for scene in ('shoebox', 'hall'):
    for suffix, what in (('', 'roulette'), ('-noroulette', 'no roulette')):
        j = load(f'prop-{scene}-rays-4096{suffix}.json')
        if j:
            r = j['ratio_full_to_bare']
            m = f'{100 * r:.0f} %'
            if 'ratio_full_to_bare_packet16' in j:  # the packet yardstick, when the JSON has it
                m += f" ({100 * j['ratio_full_to_bare_packet16']:.0f} % of the 16-wide packet loop)"
            row(f'{scene}: full frame >= 85 % of bare Embree (segments/s; 4096 x 200, {what})',
                m, r >= 0.85, f'prop-{scene}-rays-4096{suffix}.json')
def thread_scaling_row(one, two, label, digits):
    """A row for the two-thread speed-up of frame time between two bench files, if both exist."""
    j1, j2 = load(one), load(two)
    if j1 and j2:
        s = frame_ms(j1) / frame_ms(j2)
        row(label(j1), f'{s:.2f}x ({frame_ms(j1):.{digits}f} -> {frame_ms(j2):.{digits}f} ms)',
            s >= 1.85, two if 'tri' in two else one)


for scene in ('shoebox', 'hall'):
    thread_scaling_row(f'prop-{scene}-rays-4096-t1.json', f'prop-{scene}-rays-4096.json',
                       lambda j, scene=scene: f'{scene}: 2 threads >= 1.85x one (frame time, '
                       '4096 x 200, roulette)', 1)
for k in range(4):
    thread_scaling_row(f'prop-hall-tri-k{k}-t1.json', f'prop-hall-tri-k{k}-t2.json',
                       lambda j: f"hall {j['triangles']} triangles: 2 threads >= 1.85x one "
                       '(no roulette)', 0)
for scene in ('shoebox', 'hall'):
    for suffix, what in (('', 'roulette'), ('-noroulette', 'no roulette')):
        j = load(f'prop-{scene}-rays-4096{suffix}.json')
        if j:
            t = TARGET_MS[scene]
            row(f'{scene}: 4096 rays x order 200, 2 threads <= {t:g} ms ({what})',
                f"{frame_ms(j):.1f} ms median, {frame_ms(j, 'p95'):.1f} ms p95",
                frame_ms(j) <= t, f'prop-{scene}-rays-4096{suffix}.json')
j = load('prop-hall-cache.json')
if j:
    mb = j['cache']['bytes'] / 2 ** 20
    row('hall: cache <= 64 MB at 4096 x 200, tau = 1 s',
        f"{mb:.1f} MiB, {j['cache']['entries']} entries after {j['frames']} frames", mb <= 64,
        'prop-hall-cache.json')
if static4096:
    r = static4096['equal_noise_ray_ratio']
    row('equal-noise ray ratio >= 10x, static (shoebox, 4096 rays)',
        f"{r['dpc_ema']:.1f}x ({r['how']})", r['dpc_ema'] >= 10, 'noise-shoebox-static-rays-4096.json')
if walk:
    r = walk['equal_noise_ray_ratio']
    row('equal-noise ray ratio >= 4x, walking 1.4 m/s (shoebox, 4096 rays)',
        f"{r['dpc_ema']:.1f}x ({r['how']})", r['dpc_ema'] >= 4, 'noise-shoebox-walk.json')
if static4096:
    e = static4096['estimators']['dpc_ema']['error_per_frame']
    ref = static4096['reference']['own_relative_error']
    e20 = e[19]
    row('static error after 20 frames of 4000 rays <= 0.5 % (our metric)',
        f'{100 * e20:.1f} % at frame 20 (reference alone {100 * ref:.1f} %); '
        f"{100 * static4096['estimators']['dpc_ema']['error_corrected_for_reference']:.1f} % "
        f'mean over frames {static4096["warmup_frames"] + 1}..{len(e)}, corrected', e20 <= 0.005,
        'noise-shoebox-static-rays-4096.json')
print('| target | measured | met | file | other processes during the run |')
print('|---|---|---|---|---|')
for r in rows:
    print('| ' + ' | '.join(r) + ' |')

# Extra numbers for the docs.
print()
for scene in ('shoebox', 'hall'):
    j = load(f'prop-{scene}-rays-4096.json')
    if j:
        ff = j['full_frame']
        print(f"{scene} 4096x200 roulette: frame {frame_ms(j):.1f} ms = trace {ff['trace_ms']['median']:.1f}"
              f" + estimator {ff['estimator_ms']['median']:.1f}; IR synthesis {j['ir_synthesis_ms']['median']:.1f} ms;"
              f" segments/frame {ff['segments_per_frame']:.0f}, hits/frame {ff['listener_hits_per_frame']:.0f};"
              f" {j['triangles']} triangles")
if fit:
    print(f'path-tracing fit: error = {math.exp(fit[1]):.3g} * rays^{fit[0]:.3f}')
for r, j in static:
    print(f"noise static {r}: dpc_ema {j['estimators']['dpc_ema']['error_corrected_for_reference']:.4f}"
          f" pt1x {j['path_tracing']['1x']['error_corrected_for_reference']:.4f}"
          f" ratio {j['equal_noise_ray_ratio']['dpc_ema']:.1f} ({j['equal_noise_ray_ratio']['how']})"
          f" ref {j['reference']['own_relative_error']:.4f}")
for path in sorted(glob.glob(os.path.join(args.inp[0], 'live-*.json'))):
    j = json.load(open(path))
    lat = j['motion_to_sound_latency_ms']
    print(f"{os.path.basename(path)}: threads {j['threads']}, {j['rays_per_frame']} rays, "
          f"{j['frames_per_second']:.2f} frames/s, latency median {lat['median']:.1f} p95 {lat['p95']:.1f}"
          f" max {lat['max']:.1f} ms; render with swap median {j['render_time_with_ir_swap']['median_pct']:.0f} %"
          f" p99.9 {j['render_time_with_ir_swap']['p999_pct']:.0f} %; without swap median"
          f" {j['render_time_without_ir_swap']['median_pct']:.0f} % p99.9 {j['render_time_without_ir_swap']['p999_pct']:.0f} %"
          f" max {j['render_time_without_ir_swap']['max_pct']:.0f} %; xruns {j['xruns']} of {j['callbacks']}")
