#!/usr/bin/python3
"""Plots frame time, peak memory and per-source quality against the number of sources.

Reads docs/data/sources-market.json (dpc-bench sources scenes/market.json, rendering auto:
hybrid beyond 4 sources) and docs/data/sources-market-per-source.json (--rendering per_source)
and writes docs/images/sources-scaling.png: propagation pass and IR synthesis per frame (ms),
peak RSS (MB), and the worst sampled source's noise, against the number of sources, for both
tracing directions, with the issue's targets (3x one source at 64, 8x at 256, 256 MB at 64)
drawn as dotted marks. Missing files are skipped with a note on stderr.
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


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--data', default='docs/data')
    ap.add_argument('--out', default='docs/images')
    a = ap.parse_args()
    fig, (ax1, ax2, ax3) = plt.subplots(1, 3, figsize=(14, 4))
    data = os.path.join(a.data, 'sources-market.json')
    j = json.load(open(data)) if os.path.exists(data) else {}
    if not j:
        print(f'skipping {data}: missing', file=sys.stderr)
    for name, style in (('from_listeners', 'o-'), ('from_sources', 's--')):
        rs = j.get(name)
        if not rs:
            continue
        n = [r['sources'] for r in rs]
        ax1.loglog(n, [r['pass_ms_per_frame'] for r in rs], style, label=f'{name}: pass')
        ax1.loglog(n, [r['synthesis_ms_per_frame'] for r in rs], style, alpha=0.5,
                   label=f'{name}: IR synthesis')
        ax2.loglog(n, [r['peak_rss_mb'] for r in rs], style, label=name)
        ax3.semilogx(n, [worst_noise(r) for r in rs], style, label=name)
        if name == 'from_listeners':
            one = rs[0]['frame_ms']
            ax1.plot([64, 256], [3 * one, 8 * one], 'k:', marker='x',
                     label='target: 3x / 8x one source (pass + synthesis)')
    whole = os.path.join(a.data, 'sources-market-per-source.json')
    rs = json.load(open(whole)).get('from_listeners') if os.path.exists(whole) else None
    if rs:
        n = [r['sources'] for r in rs]
        ax1.loglog(n, [r['synthesis_ms_per_frame'] for r in rs], 'x:', color='grey',
                   label='from_listeners: IR synthesis, every source whole')
        ax2.loglog(n, [r['peak_rss_mb'] for r in rs], 'x:', color='grey',
                   label='from_listeners, every source whole')
    else:
        print(f'skipping {whole}: missing', file=sys.stderr)
    ax2.plot([64], [256], 'kx', label='target: 256 MB at 64 sources')
    ax1.set(xlabel='sources', ylabel='ms per frame', title='Frame time (market hall, 1 listener)')
    ax2.set(xlabel='sources', ylabel='peak RSS, MB', title='Peak memory')
    ax3.set(xlabel='sources', ylabel='relative RMS error per 10 ms bin',
            title='Worst sampled source after 20 frames')
    for ax in (ax1, ax2, ax3):
        ax.grid(True, which='both', alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    out = os.path.join(a.out, 'sources-scaling.png')
    fig.savefig(out, dpi=110)
    print(f'wrote {out}')


if __name__ == '__main__':
    main()
