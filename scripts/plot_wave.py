#!/usr/bin/python3
"""Pictures and numbers of the wave band for docs/wave.md, made with the same runs and
instruments as tests/wave/wave_test.py:

  docs/images/wave-modes.png  the modal response of a lightly absorbing 5.0 x 3.4 x 2.4 m box
                              (dpc-wave, 8 s) against the analytic mode frequencies, and each
                              of the first 20 modes' frequency and decay errors (matrix pencil)
  docs/images/wave-join.png   the shipped shoebox's third-octave levels (mean of 6 listeners) of
                              the ray-traced IR, the wave band and the joined IR (dpc-demo
                              --ir-out with wave.enabled, crossover 250 Hz)
  docs/data/wave.json         the numbers drawn

Usage: /usr/bin/python3 scripts/plot_wave.py [--build build]
"""
import argparse
import json
import os
import sys
import tempfile

import matplotlib
matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, 'tests', 'wave'))
import wave_oracle as oracle  # noqa: E402
import wave_test  # noqa: E402


def modes(build, tmp):
    size, alpha = (5.0, 3.4, 2.4), {w: 0.01 for w in ('x-', 'x+', 'y+', 'z-', 'z+')}
    alpha['y-'] = 0.05
    scene = oracle.write_box(tmp, 'modes', size, alpha, [(0.3, 0.3, 0.3)], [(4.6, 3.05, 2.1)],
                             {'max_frequency': 250})
    fs, ir, stats = wave_test.run_wave(build, scene, os.path.join(tmp, 'modes.wav'), 8.0)
    beta = {w: oracle.admittance(a) for w, a in alpha.items()}
    expected = oracle.box_modes(size, beta, wave_test.C, 20)
    neighbours = [m[0] for m in oracle.box_modes(size, beta, wave_test.C, 40)]
    rows = []
    for f, lmn, delta in expected:
        fm, dm = oracle.mode_near(ir[:, 0], fs, f, neighbours)
        rows.append({'mode': lmn, 'analytic_hz': f, 'simulated_hz': fm,
                     'analytic_decay': delta, 'simulated_decay': dm})
    spectrum = np.abs(np.fft.rfft(ir[:, 0], 4 * len(ir))) ** 2
    freqs = np.fft.rfftfreq(4 * len(ir), 1 / fs)
    keep = (freqs > 20) & (freqs < 150)
    return {'stats': stats, 'modes': rows, 'freqs': freqs[keep], 'level': 10 * np.log10(spectrum[keep])}


def plot_modes(m, path):
    fig, (a, b) = plt.subplots(2, 1, figsize=(9, 6.5), gridspec_kw={'height_ratios': [2, 1]})
    a.plot(m['freqs'], m['level'] - m['level'].max(), lw=0.7, color='k', label='dpc-wave')
    for i, r in enumerate(m['modes']):
        a.axvline(r['analytic_hz'], color='tab:red', lw=0.6, alpha=0.6,
                  label='analytic mode' if i == 0 else None)
    a.set_xlim(20, 150)
    a.set_ylim(-60, 3)
    a.set_ylabel('level (dB)')
    a.set_title('5.0 x 3.4 x 2.4 m box, walls alpha 0.01, floor 0.05: modal response')
    a.legend(loc='lower right')
    x = [r['analytic_hz'] for r in m['modes']]
    b.plot(x, [100 * (r['simulated_hz'] / r['analytic_hz'] - 1) for r in m['modes']], 'o',
           label='frequency error (%)')
    b.plot(x, [100 * (r['simulated_decay'] / r['analytic_decay'] - 1) for r in m['modes']], 's',
           label='decay-constant error (%)')
    b.axhline(0, color='k', lw=0.5)
    b.set_xlim(20, 150)
    b.set_xlabel('frequency (Hz)')
    b.set_ylabel('error (%)')
    b.legend(loc='lower left')
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def join(build, tmp):
    rays_scene, count = wave_test.shoebox_listeners(tmp, False)
    wave_scene, _ = wave_test.shoebox_listeners(tmp, True)
    rays = wave_test.render_irs(build, rays_scene, tmp, 'rays', count)
    joined = wave_test.render_irs(build, wave_scene, tmp, 'joined', count)
    fs, band, _ = wave_test.run_wave(build, rays_scene, os.path.join(tmp, 'band.wav'), 1.5)
    thirds = 1000 * 2 ** (np.arange(-15, 4) / 3)
    out = {'thirds_hz': list(thirds), 'crossover_hz': 250.0}
    for name, irs in (('rays', rays), ('wave', [band[:, k] for k in range(count)]),
                      ('joined', joined)):
        out[name] = [float(10 * np.log10(np.mean([wave_test.band_energy(
            x, fs, f * 2 ** (-1 / 6), f * 2 ** (1 / 6)) for x in irs]))) for f in thirds]
    return out


def plot_join(j, path):
    fig, a = plt.subplots(figsize=(9, 4))
    for name, style in (('rays', 'o-'), ('wave', 's-'), ('joined', 'k^-')):
        a.semilogx(j['thirds_hz'], j[name], style, label={'rays': 'ray-traced IR', 'wave':
                   'wave band (dpc-wave)', 'joined': 'joined IR (--ir-out)'}[name], ms=4)
    a.axvline(j['crossover_hz'], color='gray', ls='--', label='crossover')
    a.set_xlabel('third-octave band (Hz)')
    a.set_ylabel('energy, mean of 6 listeners (dB)')
    a.set_title('shipped shoebox (210 m^3): the wave band joined below 250 Hz')
    a.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--build', default=os.path.join(ROOT, 'build'))
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        m = modes(args.build, tmp)
        j = join(args.build, tmp)
    plot_modes(m, os.path.join(ROOT, 'docs', 'images', 'wave-modes.png'))
    plot_join(j, os.path.join(ROOT, 'docs', 'images', 'wave-join.png'))
    data = {'modes': {'stats': m['stats'], 'modes': m['modes']}, 'join': j}
    with open(os.path.join(ROOT, 'docs', 'data', 'wave.json'), 'w') as f:
        json.dump(data, f, indent=1)
    for r in m['modes']:
        print('%-10s %7.2f Hz  %+.2f %%  decay %+.1f %%' % (
            r['mode'], r['analytic_hz'], 100 * (r['simulated_hz'] / r['analytic_hz'] - 1),
            100 * (r['simulated_decay'] / r['analytic_decay'] - 1)))


if __name__ == '__main__':
    main()
