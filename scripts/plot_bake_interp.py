#!/usr/bin/env python3
"""Baked playback's interpolation error against probe spacing (dpc-bench bake-interp JSON).

Three panels: the per-band energy error and the C80 error (dB, |interpolated - simulated|,
mean and maximum over the test points and the 8 octave bands), and the error of the late
response's energy vector (first-order SH energy over energy, |r_interpolated - r_simulated|,
0 .. 2), against the probe spacing, with the Monte Carlo floor (a second independent
simulation at the same points) as a band and the issue's 1 dB target as a line (the
energy-vector panel appears when the report has it).

    dpc-bench bake-interp > docs/bench/bake-interp.json
    scripts/plot_bake_interp.py docs/bench/bake-interp.json docs/images/bake_interp_error.png
"""
import argparse
import json

import matplotlib

matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402


def panel(ax, report, key, label, target=1.0):
    rows = report['spacings']
    h = [r['spacing_m'] for r in rows]
    ax.plot(h, [r[f'{key}_mean_abs'] for r in rows], 'o-', label='mean |error|')
    ax.plot(h, [r[f'{key}_p95_abs'] for r in rows], 's--', label='95th percentile')
    ax.plot(h, [r[f'{key}_max_abs'] for r in rows], '^:', label='max')
    floor = report['monte_carlo_floor']
    ax.axhspan(0, floor[f'{key}_mean_abs'], color='0.85',
               label='Monte Carlo floor (mean |error| of a rerun)')
    if target is not None:
        ax.axhline(target, color='r', lw=0.8, label='target 1 dB')
    ax.set_xscale('log', base=2)
    ax.set_xticks(h)
    ax.set_xticklabels([f'{x:g}' for x in h])
    ax.set_xlabel('probe spacing, m')
    ax.set_ylabel(label)
    ax.grid(True, alpha=0.3)


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument('json')
    p.add_argument('png')
    a = p.parse_args()
    with open(a.json) as f:
        report = json.load(f)
    vector = 'energy_vector_mean_abs' in report['monte_carlo_floor']
    fig, axes = plt.subplots(1, 3 if vector else 2, figsize=(15 if vector else 10, 4))
    panel(axes[0], report, 'energy_db', 'band energy error, dB')
    panel(axes[1], report, 'c80_db', 'C80 error, dB')
    if vector:
        panel(axes[2], report, 'energy_vector', 'late energy vector error |dr|', None)
    axes[0].legend(fontsize=8)
    room = 'x'.join(f'{v:g}' for v in report['room_m'])
    fig.suptitle(f'Baked playback vs simulation between probes: {room} m box, scattering '
                 f'{report["scattering"]:g}, {report["points"]} points, '
                 f'{report["rays_per_frame"]} rays x {report["frames_per_response"]} frames')
    fig.tight_layout()
    fig.savefig(a.png, dpi=110)


if __name__ == '__main__':
    main()
