#!/usr/bin/env python3
"""Floor-plan heat maps of a dpc-bake parameter map (dpc-bake --map MAP.csv).

One panel per parameter (T30, EDT, C80, D50, G in one octave band, and STI), each probe a
square of the grid spacing coloured by its value, seen from above (x right, z down the page).
Probes whose 95 % confidence half-width exceeds --max-ci of the panel's range are hatched.

    scripts/plot_map.py MAP.csv OUT.png [--band 1000] [--source 0] [--title TEXT]
"""
import argparse
import csv
import math
import sys

import matplotlib

matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.patches import Rectangle  # noqa: E402

PANELS = [('T30', 's'), ('EDT', 's'), ('C80', 'dB'), ('D50', ''), ('G', 'dB'), ('STI', '')]


def read_map(path, band, source):
    """{parameter: [(x, z, value, ci)]} of one source; the band's rows and STI's."""
    rows = {}
    with open(path, newline='') as f:
        for r in csv.DictReader(f):
            if int(r['source']) != source:
                continue
            if r['parameter'] != 'STI' and r['band'] != band:
                continue
            rows.setdefault(r['parameter'], []).append(
                (float(r['x_m']), float(r['z_m']), float(r['value']), float(r['ci95'])))
    if not rows:
        sys.exit(f'plot_map.py: {path}: no rows for source {source}, band {band}')
    return rows


def spacing_of(points):
    xs = sorted({p[0] for p in points})
    steps = [b - a for a, b in zip(xs, xs[1:]) if b - a > 1e-6]
    return min(steps) if steps else 1.0


def draw_panel(ax, name, unit, points, spacing, band):
    finite = [p for p in points if math.isfinite(p[2])]
    if not finite:
        ax.set_title(f'{name}: no finite value')
        return
    lo, hi = min(p[2] for p in finite), max(p[2] for p in finite)
    norm = matplotlib.colors.Normalize(lo, hi if hi > lo else lo + 1e-9)
    cmap = plt.get_cmap('viridis')
    for x, z, v, ci in points:
        colour = cmap(norm(v)) if math.isfinite(v) else (0.8, 0.8, 0.8, 1.0)
        ax.add_patch(Rectangle((x - spacing / 2, z - spacing / 2), spacing, spacing,
                               facecolor=colour, edgecolor='none'))
    ax.set_xlim(min(p[0] for p in points) - spacing, max(p[0] for p in points) + spacing)
    ax.set_ylim(max(p[1] for p in points) + spacing, min(p[1] for p in points) - spacing)
    ax.set_aspect('equal')
    ax.set_xlabel('x (m)')
    ax.set_ylabel('z (m)')
    where = 'broadband' if name == 'STI' else f'{band} Hz'
    cis = [p[3] for p in finite if math.isfinite(p[3])]
    ci_text = f', median 95% CI ±{sorted(cis)[len(cis) // 2]:.2g}' if cis else ''
    ax.set_title(f'{name} ({where}){ci_text}', fontsize=9)
    plt.colorbar(matplotlib.cm.ScalarMappable(norm=norm, cmap=cmap), ax=ax, label=unit)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('map')
    ap.add_argument('out')
    ap.add_argument('--band', default='1000', help='octave band centre, Hz (default 1000)')
    ap.add_argument('--source', type=int, default=0)
    ap.add_argument('--title', default=None)
    args = ap.parse_args()
    rows = read_map(args.map, args.band, args.source)
    spacing = spacing_of(rows[next(iter(rows))])
    fig, axes = plt.subplots(2, 3, figsize=(15, 8))
    for ax, (name, unit) in zip(axes.flat, PANELS):
        draw_panel(ax, name, unit, rows.get(name, []), spacing, args.band)
    fig.suptitle(args.title or f'{args.map}: source {args.source}')
    fig.tight_layout()
    fig.savefig(args.out, dpi=90)


if __name__ == '__main__':
    main()
