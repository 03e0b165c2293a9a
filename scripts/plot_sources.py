#!/usr/bin/python3
"""Plots frame time, peak memory and per-source quality against the number of sources.

Reads docs/data/sources-market.json (dpc-bench sources scenes/market.json, rendering auto:
hybrid beyond 4 sources) with docs/data/sources-market-per-source.json (--rendering
per_source), and docs/data/sources-dense-hall.json (dpc-bench sources scenes/dense_hall.json),
each with its *-live.json (--keep-tolerance-db 0.5: early parts and buses kept as live),
and writes docs/images/sources-scaling.png and sources-scaling-dense-hall.png: propagation pass
and IR synthesis per frame (ms), peak RSS (MB), and the worst sampled source's noise, against
the number of sources, for both tracing directions, with the targets (TARGET_RATIO x one
source's frame, TARGET_RSS_MB at 64 sources) drawn as dotted marks. Missing files are skipped with a note on stderr.
Needs matplotlib (Debian: python3-matplotlib).
Usage: /usr/bin/python3 scripts/plot_sources.py [--data docs/data] [--out docs/images]
"""
import argparse
import json
import os
import sys

import matplotlib
matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402


def worst_noise(row):
    return max((q['noise'] for q in row['quality']), default=float('nan'))


# The targets drawn: frame (pass + synthesis) at most these multiples of one source's frame,
# and peak RSS at 64 sources.
TARGET_RATIO = {64: 2.5, 256: 6.0}
TARGET_RSS_MB = 256

# Per figure: data file, optional every-source-whole comparison, optional run with the IRs
# kept as a live session keeps them (--keep-tolerance-db), title, output.
FIGURES = [
    ('sources-market.json', 'sources-market-per-source.json', 'sources-market-live.json',
     'market hall', 'sources-scaling.png'),
    ('sources-dense-hall.json', None, 'sources-dense-hall-live.json', 'dense hall, 20 x 15 x 4 m',
     'sources-scaling-dense-hall.png'),
]


def plot_rows(j, ax1, ax2, ax3):
    for name, style in (('from_listeners', 'o-'), ('from_sources', 's--')):
        rs = j.get(name)
        if not rs:
            continue
        n = [r['sources'] for r in rs]
        ax1.loglog(n, [r['pass_ms_per_frame'] for r in rs], style, label=f'{name}: pass')
        ax1.loglog(n, [r['synthesis_ms_per_frame'] for r in rs], style, alpha=0.5,
                   label=f'{name}: IR synthesis')
        ax1.loglog(n, [r['frame_ms'] for r in rs], style, color='black', alpha=0.7,
                   label=f'{name}: frame (pass + synthesis)')
        ax2.loglog(n, [r['peak_rss_mb'] for r in rs], style, label=name)
        ax3.semilogx(n, [worst_noise(r) for r in rs], style, label=name)
        if name == 'from_listeners' and rs[0]['sources'] == 1:
            one = rs[0]['frame_ms']
            counts = sorted(TARGET_RATIO)
            ax1.plot(counts, [TARGET_RATIO[c] * one for c in counts], 'k:', marker='x',
                     label='target: %s x one source (pass + synthesis)' %
                     ' / '.join('%g' % TARGET_RATIO[c] for c in counts))


def listener_rows(path):
    """The from_listeners rows of a comparison file, or None (noted on stderr)."""
    rs = json.load(open(path)).get('from_listeners') if os.path.exists(path) else None
    if not rs:
        print(f'skipping {path}: missing', file=sys.stderr)
    return rs


def plot_whole(path, ax1, ax2):
    rs = listener_rows(path)
    if not rs:
        return
    n = [r['sources'] for r in rs]
    ax1.loglog(n, [r['synthesis_ms_per_frame'] for r in rs], 'x:', color='grey',
               label='from_listeners: IR synthesis, every source whole')
    ax2.loglog(n, [r['peak_rss_mb'] for r in rs], 'x:', color='grey',
               label='from_listeners, every source whole')


def plot_kept(path, ax1):
    rs = listener_rows(path)
    if not rs:
        return
    n = [r['sources'] for r in rs]
    ax1.loglog(n, [r['frame_ms'] for r in rs], 'd-', color='tab:green',
               label='from_listeners: frame, IRs kept as live (still listener)')


def figure(data_dir, out_dir, data, whole, kept, title, out):
    path = os.path.join(data_dir, data)
    if not os.path.exists(path):
        print(f'skipping {path}: missing', file=sys.stderr)
        return
    fig, (ax1, ax2, ax3) = plt.subplots(1, 3, figsize=(14, 4))
    plot_rows(json.load(open(path)), ax1, ax2, ax3)
    if whole:
        plot_whole(os.path.join(data_dir, whole), ax1, ax2)
    if kept:
        plot_kept(os.path.join(data_dir, kept), ax1)
    ax2.plot([64], [TARGET_RSS_MB], 'kx', label=f'target: {TARGET_RSS_MB} MB at 64 sources')
    ax1.set(xlabel='sources', ylabel='ms per frame', title=f'Frame time ({title}, 1 listener)')
    ax2.set(xlabel='sources', ylabel='peak RSS, MB', title='Peak memory')
    ax3.set(xlabel='sources', ylabel='relative RMS error per 10 ms bin',
            title='Worst sampled source after 20 frames')
    for ax in (ax1, ax2, ax3):
        ax.grid(True, which='both', alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(out_dir, out), dpi=110)
    print(f'wrote {os.path.join(out_dir, out)}')


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--data', default='docs/data')
    ap.add_argument('--out', default='docs/images')
    a = ap.parse_args()
    for data, whole, kept, title, out in FIGURES:
        figure(a.data, a.out, data, whole, kept, title, out)


if __name__ == '__main__':
    main()
