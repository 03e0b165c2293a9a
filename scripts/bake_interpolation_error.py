#!/usr/bin/env python3
"""Error of interpolating baked responses between probes, against probe spacing.

For each spacing, bakes the scene's grid (dpc-bake --spacing) and, as the truth, the points
midway between grid probes (dpc-bake --probes: cell centres of four probes, or midpoints of
two where the grid is one row deep). At each truth point the reverberant part of the
neighbours' responses (energy minus their direct sound) is averaged with inverse-distance
weights and the truth point's own direct sound is added, as a player that keeps the direct
sound live would do. Reported per spacing: the per-band energy error (dB, 125 Hz .. 4 kHz,
mean and max of |error| over points and bands) and the C80 error at 1 kHz (dB), with the
truth's own Monte Carlo interval for scale. The room is convex, so every neighbour sees the
point (no visibility test is needed here).

    scripts/bake_interpolation_error.py [--scene scenes/shoebox.json] [--build build]
        [--spacings 0.5 1 2 4] [--rays 2000] [--frames 8] [--json OUT.json] [--png OUT.png]
Needs h5py (Debian python3-h5py).
"""
import argparse
import json
import os
import subprocess
import tempfile

import h5py
import numpy as np

BANDS = slice(1, 7)  # 125 Hz .. 4 kHz
K1000 = 4


def bake(args, out, extra):
    cmd = [os.path.join(args.build, 'apps', 'dpc-bake'), args.scene, '--out', out, '--rays',
           str(args.rays), '--frames', str(args.frames), '--quiet'] + extra
    subprocess.run(cmd, check=True)
    with h5py.File(out, 'r') as f:
        return {k: f[k][:] for k in ('probes/position', 'energy', 'direct/delay_s',
                                      'direct/energy', 'parameters_ci95')}


def midpoints(grid, spacing):
    """Points between neighbouring probes: centres of 2x2 cells, or of pairs along x."""
    pos = grid['probes/position']
    key = {(round(p[0] / spacing * 2), round(p[2] / spacing * 2)): p for p in pos}
    pts = []
    for (i, k), p in key.items():
        quad = [(i + 2, k), (i, k + 2), (i + 2, k + 2)]
        if all(q in key for q in quad):
            pts.append(p + np.array([spacing / 2, 0, spacing / 2]))
    if not pts:
        pts = [p + np.array([spacing / 2, 0, 0]) for (i, k), p in key.items() if (i + 2, k) in key]
    return np.array(pts)


def reverberant(d, idx):
    """energy[idx, source 0] minus its direct sound: [B, 8]."""
    e = d['energy'][idx, 0].astype(np.float64).copy()
    k = int(d['direct/delay_s'][idx, 0] / 1e-3)
    e[k] -= d['direct/energy'][idx, 0]
    return e


def c80(e):
    onset = np.argmax(e.sum(axis=1) > 0)
    split = onset + 80
    return 10 * np.log10(e[onset:split, K1000].sum() / e[split:, K1000].sum())


def measure(args, spacing, work):
    grid = bake(args, os.path.join(work, 'grid.h5'), ['--spacing', str(spacing)])
    pts = midpoints(grid, spacing)
    listing = os.path.join(work, 'points.txt')
    np.savetxt(listing, pts)
    truth = bake(args, os.path.join(work, 'truth.h5'), ['--probes', listing])
    band_err, c80_err = [], []
    for t, p in enumerate(truth['probes/position']):
        dist = np.linalg.norm(grid['probes/position'] - p, axis=1)
        near = np.where(dist < spacing * 0.75)[0]
        w = 1 / dist[near]
        w /= w.sum()
        est = sum(wi * reverberant(grid, n) for wi, n in zip(w, near))
        k = int(truth['direct/delay_s'][t, 0] / 1e-3)
        est[k] += truth['direct/energy'][t, 0]
        ref = truth['energy'][t, 0].astype(np.float64)
        band_err += list(10 * np.log10(est.sum(axis=0)[BANDS] / ref.sum(axis=0)[BANDS]))
        c80_err.append(c80(est) - c80(ref))
    band_err, c80_err = np.abs(band_err), np.abs(c80_err)
    ci = truth['parameters_ci95'][:, 0, K1000]
    return {'spacing_m': spacing, 'grid_probes': len(grid['probes/position']),
            'points': len(pts), 'band_energy_error_db': {'mean': band_err.mean(),
                                                         'max': band_err.max()},
            'c80_error_db_1k': {'mean': c80_err.mean(), 'max': c80_err.max()},
            'truth_ci95_g_db_1k': float(np.nanmedian(ci[:, 6])),
            'truth_ci95_c80_db_1k': float(np.nanmedian(ci[:, 4]))}


def plot(rows, path):
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    s = [r['spacing_m'] for r in rows]
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(s, [r['band_energy_error_db']['mean'] for r in rows], 'o-', label='band energy, mean')
    ax.plot(s, [r['band_energy_error_db']['max'] for r in rows], 'o--', label='band energy, max')
    ax.plot(s, [r['c80_error_db_1k']['mean'] for r in rows], 's-', label='C80 1 kHz, mean')
    ax.plot(s, [r['truth_ci95_g_db_1k'] for r in rows], ':', label='truth G 95% CI (noise)')
    ax.axhline(1.0, color='grey', lw=0.8)
    ax.set_xscale('log', base=2)
    ax.set_xticks(s, [str(v) for v in s])
    ax.set_xlabel('probe spacing (m)')
    ax.set_ylabel('|interpolated - simulated| (dB)')
    ax.set_title('Interpolation between baked probes vs direct simulation (shoebox)')
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=90)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--scene', default='scenes/shoebox.json')
    ap.add_argument('--build', default='build')
    ap.add_argument('--spacings', type=float, nargs='+', default=[0.5, 1, 2, 4])
    ap.add_argument('--rays', type=int, default=2000)
    ap.add_argument('--frames', type=int, default=8)
    ap.add_argument('--json')
    ap.add_argument('--png')
    args = ap.parse_args()
    rows = []
    with tempfile.TemporaryDirectory() as work:
        for s in args.spacings:
            rows.append(measure(args, s, work))
            print(json.dumps(rows[-1]))
    if args.json:
        with open(args.json, 'w') as f:
            json.dump({'scene': args.scene, 'rays': args.rays, 'frames': args.frames,
                       'rows': rows}, f, indent=1)
    if args.png:
        plot(rows, args.png)


if __name__ == '__main__':
    main()
