"""The engine's early energy against dpc-wave's FDTD in the 24 m cube of tests/wave/wave_test.py
(faces absorbing, rigid obstacles inside): the shared part of scripts/door_wave.py and
scripts/obstacle_wave.py.

Per receiver and octave:
  FDTD    the windowed octave level of dpc-wave's IR over the free field's at that distance:
          from 4 ms before the direct sound to 6 ms before the first path that touches a face
          of the cube (wave_test.first_wall_path), the free field through the same pulse and
          window (as wave_test.screen_compare does)
  engine  dpc-demo --er-out's direct row (the direct sound with its edge and slit paths) plus
          every energy-response bin before the window's end (the exact and the traced
          reflections), over the free field: energies summed, as the IR carries them
"""
import argparse
import json
import math
import os
import subprocess
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, 'tests', 'wave'))
import wave_oracle as oracle  # noqa: E402
import wave_test as wt  # noqa: E402

SIZE = wt.SCREEN_SIZE  # m, the cube's side
OCTAVES = [63.0, 125.0]


def write_scene(tmp, name, quads, source, receivers):
    """The cube with `quads` (material -> list of quads; every material rigid, the cube's
    markers absorbing), one source and the receivers; written twice: for dpc-wave and, as
    rays_scene(path), for the engine's renders without the wave band."""
    q = dict(quads)
    q['marker'] = wt.marker_quads(SIZE)
    absorption = {m: 0.0 for m in q}
    absorption['marker'] = 1.0
    path = oracle.write_mesh(tmp, name, q, absorption, [source], receivers,
                             {'max_frequency': wt.SCREEN_FMAX, 'crossover_hz': 100,
                              'grid_spacing': wt.SCREEN_SPACING}, ir_length=0.1)
    with open(path) as f:
        scene = json.load(f)
    scene['sources'][0]['signal'] = os.path.join(ROOT, 'scenes', 'signals', 'percussion.wav')
    for m in scene['materials'].values():
        m['scattering'] = 0.0
    scene['propagation'].update({'exact_order': 2, 'rays_per_frame': 2000, 'max_order': 4,
                                 'air_absorption': False})
    with open(path, 'w') as f:
        json.dump(scene, f, indent=1)
    # The wave band joins the IR only, not --er-out, and would simulate the cube per render.
    scene['wave']['enabled'] = False
    with open(rays_scene(path), 'w') as f:
        json.dump(scene, f, indent=1)
    return path


def rays_scene(path):
    """The scene file of `path` without the wave band (write_scene writes both)."""
    return path[:-len('.json')] + '_rays.json'


def window_end(source, p):
    return wt.first_wall_path(source, p, SIZE) / wt.C - 0.006


def fdtd_levels(build, scene, tmp, name, source, receivers):
    """Per receiver, the windowed octave levels over the free field's (dB)."""
    fs, ir, stats = wt.run_wave(build, scene, os.path.join(tmp, name + '.wav'), 0.08)
    out = []
    for k, p in enumerate(receivers):
        dist = float(np.linalg.norm(np.subtract(p, source)))
        t_end = window_end(source, p)
        free = wt.pulse_filtered(oracle.dirac_ir(dist / wt.C, 1 / dist, fs, t_end), fs,
                                 stats['step_rate_hz'])
        a, b = max(int(round((dist / wt.C - 0.004) * fs)), 0), int(round(t_end * fs))
        w = wt.tukey(b - a)
        sim = wt.band_levels(ir[a:b, k] * w, fs, OCTAVES)
        ref = wt.band_levels(free[a:b] * w, fs, OCTAVES)
        out.append((10 * np.log10(sim / ref)).tolist())
    return out


def engine_levels(build, scene, tmp, name, source, receivers):
    """Per receiver, [direct row, direct row + bins before the window's end] at each octave,
    over the free field (dB)."""
    out = []
    for k, p in enumerate(receivers):
        er = os.path.join(tmp, '%s_%d.csv' % (name, k))
        subprocess.run([os.path.join(build, 'apps', 'dpc-demo'), rays_scene(scene), '--offline',
                        os.path.join(tmp, 'out.wav'), '--er-out', er, '--listener', 'l%d' % k,
                        '--duration', '0.3', '--quiet'], check=True, capture_output=True)
        free = 1 / (4 * math.pi * float(np.linalg.norm(np.subtract(p, source))) ** 2)
        direct, early = np.zeros(len(OCTAVES)), np.zeros(len(OCTAVES))
        with open(er) as f:
            for line in f:
                r = line.strip().split(',')
                if len(r) < 3 + len(OCTAVES) or r[0].startswith('#') or r[0] == 'source':
                    continue
                values = np.array([float(v) for v in r[3:3 + len(OCTAVES)]])
                if r[1] == 'direct':
                    direct += values
                elif float(r[2]) < window_end(source, p):
                    early += values
        row = []
        for i in range(len(OCTAVES)):
            row.append([10 * math.log10(max(direct[i], 1e-30) / free),
                        10 * math.log10(max(direct[i] + early[i], 1e-30) / free)])
        out.append(row)
    return out


def write_json(results, path):
    """Writes `results` to path whole or not at all."""
    partial = path + '.partial'
    with open(partial, 'w') as f:
        json.dump(results, f, indent=1)
    os.replace(partial, path)


def parse_args(description, tool, check_help):
    """The command line both comparisons take: --build, --json (docs/data/<tool>.json),
    --plot, --engine-only and --check."""
    ap = argparse.ArgumentParser(description=description)
    ap.add_argument('--build', default=os.path.join(ROOT, 'build'))
    ap.add_argument('--json', default=os.path.join(ROOT, 'docs', 'data', tool + '.json'))
    ap.add_argument('--plot', help='write the figure here (PNG)')
    ap.add_argument('--engine-only', action='store_true',
                    help="take the FDTD levels from --json's file instead of simulating")
    ap.add_argument('--check', action='store_true', help=check_help)
    args = ap.parse_args()
    if not os.access(os.path.join(args.build, 'apps', 'dpc-demo'), os.X_OK):
        sys.exit('%s: --build %s: no dpc-demo in apps/' % (tool.replace('-', '_'), args.build))
    return args


def stored_levels(path, names, tool):
    """The FDTD levels stored in `path` (a previous run's --json), which must hold every
    configuration in `names`; exits with one line naming the file otherwise."""
    try:
        with open(path) as f:
            stored = json.load(f)
        missing = [n for n in names if n not in stored]
    except (OSError, ValueError) as e:
        sys.exit('%s: %s: cannot read the stored FDTD levels (%s)' % (tool, path, e))
    if missing:
        sys.exit('%s: %s: no FDTD levels for %s' % (tool, path, ', '.join(missing)))
    return stored
