#!/usr/bin/python3
"""Plots the cache memory budget sweep and the equal-noise ratios by reflection order.

Reads docs/data/budget-{shoebox,room,hall}.json (dpc-bench budget) and
docs/data/noise-by-order-{shoebox,hall}.json (dpc-bench noise); writes
docs/images/budget-memory.png (entries and bytes vs rays per frame, budget line),
docs/images/budget-bias.png (energy ratio budgeted / unbounded vs rays per frame) and
docs/images/noise-by-order.png (equal-noise ray ratio per order range). Missing files are
skipped with a note on stderr. Needs matplotlib (Debian: python3-matplotlib).
Usage: /usr/bin/python3 scripts/plot_budget.py [--data docs/data] [--out docs/images]
"""
import argparse
import json
import os
import sys

import matplotlib
matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402


def load(path):
    if not os.path.exists(path):
        print(f'skipping {path}: missing', file=sys.stderr)
        return None
    with open(path) as f:
        return json.load(f)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--data', default='docs/data')
    ap.add_argument('--out', default='docs/images')
    a = ap.parse_args()
    sweeps = {n: load(os.path.join(a.data, f'budget-{n}.json')) for n in ('shoebox', 'room', 'hall')}
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))
    fig2, ax3 = plt.subplots(figsize=(5, 4))
    for name, j in sweeps.items():
        if not j:
            continue
        pts = j['points']
        name = f"{name} ({j['weighting']})"
        rays = [p['rays_per_frame'] for p in pts]
        ax1.loglog(rays, [p['entries'] for p in pts], 'o-', label=f'{name}: path entries (budget)')
        ax1.loglog(rays, [p['unbounded_entries'] for p in pts], 'x--', label=f'{name}: unbounded')
        ax2.semilogx(rays, [p['bytes'] / 1048576 for p in pts], 'o-', label=name)
        ax3.semilogx(rays, [100 * (p['energy_ratio_vs_unbounded'] - 1) for p in pts], 'o-',
                     label=name)
        budget = pts[0]['budget_bytes'] / 1048576
    ax2.axhline(budget, color='k', lw=0.8, ls=':', label='budget')
    ax1.set(xlabel='rays per frame', ylabel='path entries', title='Path entries at a 1 MB budget (tau 1 s)')
    ax2.set(xlabel='rays per frame', ylabel='MB held', title='Bytes held (max over frames)')
    ax2.set_ylim(0, budget * 1.2)
    ax3.set(xlabel='rays per frame', ylabel='energy, % vs unbounded cache',
            title='Budget bias (same rays)')
    for ax in (ax1, ax2, ax3):
        ax.grid(True, which='both', alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(a.out, 'budget-memory.png'), dpi=110)
    fig2.tight_layout()
    fig2.savefig(os.path.join(a.out, 'budget-bias.png'), dpi=110)

    fig3, ax = plt.subplots(figsize=(6, 4))
    width = 0.35
    for i, name in enumerate(('shoebox', 'hall')):
        j = load(os.path.join(a.data, f'noise-by-order-{name}.json'))
        if not j:
            continue
        r = j['equal_noise_ray_ratio_by_order']
        keys = list(r.keys())
        ax.bar([k + i * width for k in range(len(keys))], [r[k] for k in keys], width, label=name)
        ax.set_xticks([k + width / 2 for k in range(len(keys))], keys)
    ax.axhline(10, color='k', lw=0.8, ls=':', label='target 10')
    ax.set(xlabel='reflection orders (as delay ranges)', ylabel='equal-noise ray ratio',
           title='Plain path tracing rays for the DPC noise / DPC rays')
    ax.legend()
    fig3.tight_layout()
    fig3.savefig(os.path.join(a.out, 'noise-by-order.png'), dpi=110)


if __name__ == '__main__':
    main()
