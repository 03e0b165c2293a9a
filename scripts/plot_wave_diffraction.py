#!/usr/bin/python3
"""The wave band's diffraction checks as a picture for docs/wave.md, made with the same runs
and instruments as tests/wave/wave_test.py (screen, slit):

  docs/images/wave-diffraction.png  for a thin rigid half-plane (top) and a 3 m slit (bottom)
                                    in a 24 m cube with absorbing faces (dpc-wave, maximum
                                    250 Hz, spacing 0.125 m): the section through the source,
                                    one shadow receiver's windowed response against the oracle
                                    (Biot-Tolstoy edge diffraction plus the geometric terms,
                                    through the same pulse and window), and every receiver's
                                    63 and 125 Hz octave level over the free field's
  docs/data/wave-diffraction.json   the numbers drawn

Usage: /usr/bin/python3 scripts/plot_wave_diffraction.py [--build build]
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
import wave_test as wt  # noqa: E402

CASES = [
    ('half-plane', [(0.0, wt.SCREEN_EDGE)], [(-np.inf, wt.SCREEN_EDGE)], wt.SCREEN_SOURCE,
     wt.SCREEN_RECEIVERS, 1),
    ('3 m slit', [(0.0, wt.SLIT[0]), (wt.SLIT[1], wt.SCREEN_SIZE)],
     [(-np.inf, wt.SLIT[0]), (wt.SLIT[1], np.inf)], wt.SLIT_SOURCE, wt.SLIT_RECEIVERS, 2),
]


def run(build, tmp):
    out = []
    for name, screens, oracle_screens, source, receivers, shown in CASES:
        details = []
        wt.screen_compare(build, tmp, name.replace(' ', '_'), screens, oracle_screens, source,
                          receivers, name, details)
        out.append({'name': name, 'screens': screens, 'source': source, 'shown': shown,
                    'receivers': details})
    return out


def plot(cases, path):
    fig, axes = plt.subplots(len(cases), 3, figsize=(13, 4.2 * len(cases)),
                             gridspec_kw={'width_ratios': [1, 1.5, 1.5]})
    for row, case in zip(axes, cases):
        geo, trace, levels = row
        for lo, hi in case['screens']:
            geo.plot([wt.SCREEN_X] * 2, [lo, hi], color='k', lw=2.5)
        geo.plot(case['source'][0], case['source'][1], 'r*', ms=12, label='source')
        for k, r in enumerate(case['receivers']):
            x, y, z = r['receiver']
            geo.plot(x, y, 'o', color='tab:blue', ms=6)
            geo.annotate('%d' % (k + 1) + ('' if z == case['source'][2] else "'"), (x, y),
                         xytext=(4, 3), textcoords='offset points', fontsize=8)
        geo.set_xlim(7, 18)
        geo.set_ylim(6, 21)
        geo.set_aspect('equal')
        geo.set_xlabel('x (m)')
        geo.set_ylabel('y (m)')
        geo.set_title('%s: section z = 12 m (\' off it)' % case['name'], fontsize=10)
        geo.legend(fontsize=8, loc='lower left')
        r = case['receivers'][case['shown']]
        t = r['window_s'][0] + np.arange(len(r['simulated'])) / r['fs']
        trace.plot(1e3 * t, r['simulated'], color='k', lw=1.2, label='dpc-wave')
        trace.plot(1e3 * t, r['oracle'], color='tab:red', lw=1, ls='--',
                   label='Biot-Tolstoy + geometric')
        trace.set_xlabel('time (ms), the window of the comparison')
        trace.set_ylabel('IR (1/(sqrt(4 pi) m) per sample)')
        trace.set_title('receiver %d, %s' % (case['shown'] + 1, r['what']), fontsize=10)
        trace.legend(fontsize=8)
        n = len(case['receivers'])
        k = np.arange(n) + 1
        for j, (f, colour) in enumerate(zip(wt.OCTAVES, ('tab:blue', 'tab:orange'))):
            ref = np.array([x['oracle_re_free_db'][j] for x in case['receivers']])
            sim = ref + np.array([x['difference_db'][j] for x in case['receivers']])
            levels.plot(k + 0.1 * (j - 0.5), ref, 's', mfc='none', color=colour, ms=9,
                        label='%.0f Hz oracle' % f)
            levels.plot(k + 0.1 * (j - 0.5), sim, 'x', color=colour, ms=8,
                        label='%.0f Hz dpc-wave' % f)
        levels.axhline(0, color='grey', lw=0.6)
        low, high = levels.get_ylim()
        levels.set_ylim(low, high + 0.35 * (high - low))  # room for the legend
        levels.set_xticks(k)
        levels.set_xlabel('receiver')
        levels.set_ylabel('octave level over the free field (dB)')
        worst = max(abs(d) for x in case['receivers'] for d in x['difference_db'])
        levels.set_title('octave levels (worst difference %.2f dB)' % worst, fontsize=10)
        levels.legend(fontsize=8, ncol=2, loc='upper left')
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--build', default=os.path.join(ROOT, 'build'))
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        cases = run(os.path.abspath(args.build), tmp)
    plot(cases, os.path.join(ROOT, 'docs', 'images', 'wave-diffraction.png'))
    data = [{'name': c['name'], 'screens_y_m': c['screens'], 'source': c['source'],
             'receivers': [{k: v for k, v in r.items() if k not in ('simulated', 'oracle', 'fs')}
                           for r in c['receivers']]} for c in cases]
    with open(os.path.join(ROOT, 'docs', 'data', 'wave-diffraction.json'), 'w') as f:
        json.dump(data, f, indent=1)
    print('wrote docs/images/wave-diffraction.png and docs/data/wave-diffraction.json')


if __name__ == '__main__':
    main()
