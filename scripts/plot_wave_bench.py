#!/usr/bin/python3
"""Draws docs/images/wave-cost.png from `dpc-bench wave` JSON (docs/data/wave-bench.json): wall
seconds per simulated second and state memory against the room's volume at each maximum
frequency, and the predicted speed-up over MPI ranks (the benchmark's slab model).

Usage: build/bench/dpc-bench wave > docs/data/wave-bench.json
       /usr/bin/python3 scripts/plot_wave_bench.py [docs/data/wave-bench.json]
"""
import json
import os
import sys

import matplotlib
matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def main():
    path = sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, 'docs', 'data',
                                                              'wave-bench.json')
    with open(path) as f:
        report = json.load(f)
    runs = report['runs']
    fig, (a, b, c) = plt.subplots(1, 3, figsize=(13, 3.8))
    for hz in sorted({r['max_frequency_hz'] for r in runs}):
        rs = [r for r in runs if r['max_frequency_hz'] == hz]
        v = [r['volume_m3'] for r in rs]
        a.loglog(v, [r['s_per_simulated_s_per_m3'] * r['volume_m3'] for r in rs], 'o-',
                 label='%g Hz' % hz)
        b.loglog(v, [r['state_bytes'] / 1e6 for r in rs], 'o-', label='%g Hz' % hz)
        big = max(rs, key=lambda r: r['volume_m3'])
        c.plot([x['ranks'] for x in big['predicted_rank_scaling']],
               [x['predicted_speedup'] for x in big['predicted_rank_scaling']], 'o-',
               label='%g Hz, %g m^3' % (hz, big['volume_m3']))
    a.set_xlabel('room volume (m^3)')
    a.set_ylabel('wall s per simulated s (all bands)')
    b.set_xlabel('room volume (m^3)')
    b.set_ylabel('solver state (MB)')
    c.set_xlabel('MPI ranks (slabs; model)')
    c.set_ylabel('predicted speed-up')
    for ax in (a, b, c):
        ax.grid(True, which='both', alpha=0.3)
        ax.legend()
    a.set_title('time (2 cores)')
    b.set_title('memory')
    c.set_title('predicted rank scaling')
    fig.tight_layout()
    fig.savefig(os.path.join(ROOT, 'docs', 'images', 'wave-cost.png'), dpi=110)


if __name__ == '__main__':
    main()
