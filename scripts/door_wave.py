#!/usr/bin/python3
"""Doors against a wave simulation: a doorway in a rigid wall, open and with its leaf swung
60-90 degrees beside the line of sight, at 63 and 125 Hz, the engine's early energy against
dpc's FDTD solver (dpc-wave), an instrument that shares no code with the ray and edge model.

The scene: the 24 m cube of tests/wave/wave_test.py (faces absorbing, the wave band's screen
tests use it), a rigid wall of zero thickness across it in the plane x = 12 m with a doorway
1.0 m wide and 2.125 m high (y 11-13.125 m, z 11.5-12.5 m: every edge on a plane between
nodes of the 0.125 m grid), and a rigid leaf 1.0 x 2.125 m hinged at the doorway's side
z = 11.5 m, swung into the listener's side; no floor, so that nothing but the doorway and the
leaf shapes the first 50 ms. The source 3 m in front of the doorway at its middle, five
receivers behind it: on the axis 3 and 4.5 m behind, 1.5 m to either side (behind the wall,
in the jambs' shadow) and 0.9 m above the lintel's height.

Per configuration, receiver and octave (63, 125 Hz):
  FDTD    the windowed octave level of dpc-wave's IR over the free field's at that distance:
          from 4 ms before the direct sound to 6 ms before the first path that touches a face
          of the cube (wave_test.first_wall_path), the free field through the same pulse and
          window (as wave_test.screen_compare does; dpc-wave matches Biot-Tolstoy's half-plane
          within 0.4 dB there, docs/wave.md)
  engine  dpc-demo --er-out's direct row (the direct sound with its edge and slit paths) plus
          every energy-response bin before the window's end (the exact and the traced
          reflections off the leaf), over the free field: energies summed, as the IR carries them
  difference  engine - FDTD, dB

--check fails unless, on the doorway's axis (the receivers 3 and 4.5 m behind it, the line of
sight through the doorway), at 63 and 125 Hz, with the doorway open and the leaf at 60-90
degrees, the engine is within 7 dB of the FDTD level (FDTD's own spread is 0.4 dB at these
edges; first-order diffraction against a wave solution at kd of 1-2 is the rest: the open
doorway reads +0.7 to +1.3 dB, its edges taken at their lengths (engine/finite_edge.h), and the
leaf at 80 degrees reads +6.9 dB at 63 Hz 3 m behind, where the first-order Biot-Tolstoy-Medwin
field of the edges the listener sees reads 7.8 dB above the FDTD: the engine follows first
order, and the leaf's and the frame's waves on each other are missing; 4.5 dB held while every
edge was infinite, 5 dB while this mesh's T-junctions made its lintel and sill 24 m long,
engine/sealed_edges.h). At 85 and 90 degrees the leaf's face reflects toward the axis: its
image source carries the share a face smaller than the first Fresnel zone reflects
(engine/small_reflectors.h; +10 to +12 dB at 90 degrees while it carried the whole
reflection); at 85 degrees, 3 m behind, traced rays that reach the listener sphere off the leaf
where no exact path reaches its centre keep their whole reflection (+6.8 dB at 63 Hz).
Beside the doorway (a second set): the source 4 m in front of the wall and 1.5 m to the hinge
side, so that the wall hides every receiver; the leaf hung with a 1 cm gap at its hinge (as
scenes/two_rooms.json's), swung 70-90 degrees; four receivers behind it: 4.5 m behind the wall
0.3 and 0.8 m in from the hinge jamb, 3 m behind 0.2 m in, and 1.5 m behind in the pocket
between the leaf and the wall. Every path there turns round the hinge jamb and passes the leaf
by its hinge gap or its free rim. --check also fails unless, for each of them at 63 and 125 Hz,
what the leaf takes away (the leaf's level less the open doorway's) is the FDTD's within 3 dB:
the doorway's own error behind the wall (up to 3.5 dB, the first set's table) cancels, and the
FDTD has the leaf take 1.1-2.6 dB at 63 Hz and up to 3.3 dB at 125 Hz.
--engine-only takes the FDTD levels from --json's file instead of simulating (seconds instead
of minutes).

Usage: /usr/bin/python3 scripts/door_wave.py [--build build] [--json docs/data/door-wave.json]
           [--plot docs/images/door-wave.png] [--engine-only] [--check]
"""
import math
import os
import sys
import tempfile

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, 'scripts'))
import wave_compare as wc  # noqa: E402

SIZE, WALL_X = 24.0, 12.0
DOOR_Y, DOOR_H, DOOR_Z, DOOR_W = 11.0, 2.125, 11.5, 1.0
SOURCE = (9.0, 12.05, 12.0)
RECEIVERS = [((15.0, 12.05, 12.0), 'axis 3 m'), ((16.5, 12.05, 12.0), 'axis 4.5 m'),
             ((15.0, 12.05, 10.5), 'hinge side'), ((15.0, 12.05, 13.5), 'latch side'),
             ((15.0, 14.0, 12.0), 'above lintel')]
ON_AXIS = ('axis 3 m', 'axis 4.5 m')
ANGLES = [None, 60.0, 70.0, 80.0, 85.0, 90.0]  # None: the doorway open
CHECKED_ANGLES = ANGLES
OCTAVES = wc.OCTAVES
TOLERANCE_DB = 7.0  # dB; see the module comment
BESIDE_SOURCE = (8.0, 12.05, 10.0)
BESIDE_RECEIVERS = [((16.5, 12.05, 11.8), '4.5 m behind, 0.3 m in'),
                    ((16.5, 12.05, 12.3), '4.5 m behind, 0.8 m in'),
                    ((15.0, 12.05, 11.7), '3 m behind, 0.2 m in'),
                    ((13.5, 12.05, 11.3), 'pocket, 1.5 m behind')]
BESIDE_ANGLES = [None, 70.0, 75.0, 80.0, 85.0, 90.0]
HINGE_GAP = 0.01  # m, between the jamb and the leaf's hinge end (FDTD: below its 0.125 m grid)
LEAF_TOLERANCE_DB = 3.0


def name_of(angle, beside=False):
    name = 'open' if angle is None else 'leaf %.0f deg' % angle
    return 'beside: ' + name if beside else name


def quads(angle, hinge_gap=0.0):
    """The wall round the doorway (four panels across the cube) and the leaf swung `angle`
    degrees from the wall's plane into x > WALL_X (none: open), hinge_gap (m) from the jamb
    and as much short of the latch jamb; wave_compare adds the cube's markers."""
    x, s, y0, y1, z0, z1 = WALL_X, SIZE, DOOR_Y, DOOR_Y + DOOR_H, DOOR_Z, DOOR_Z + DOOR_W
    out = {'wall': [((x, 0, 0), (x, y0, 0), (x, y0, s), (x, 0, s)),
                    ((x, y1, 0), (x, s, 0), (x, s, s), (x, y1, s)),
                    ((x, y0, 0), (x, y1, 0), (x, y1, z0), (x, y0, z0)),
                    ((x, y0, z1), (x, y1, z1), (x, y1, s), (x, y0, s))]}
    if angle is not None:
        a = math.radians(angle)
        hinge, free = hinge_gap, DOOR_W - hinge_gap
        hx, hz = x + hinge * math.sin(a), z0 + hinge * math.cos(a)
        fx, fz = x + free * math.sin(a), z0 + free * math.cos(a)
        out['leaf'] = [((hx, y0, hz), (hx, y1, hz), (fx, y1, fz), (fx, y0, fz))]
    return out


def run_set(args, stored, tmp, angles, beside):
    """Per configuration of one set, its FDTD levels (simulated, or from `stored`) and the
    engine's."""
    source, receivers = (BESIDE_SOURCE, BESIDE_RECEIVERS) if beside else (SOURCE, RECEIVERS)
    points = [p for p, _ in receivers]
    results = {}
    for angle in angles:
        name = name_of(angle, beside)
        file = 'open' if angle is None else 'leaf%03d' % int(angle)
        file = 'beside_' + file if beside else file
        scene = wc.write_scene(tmp, file, quads(angle, HINGE_GAP if beside else 0.0), source,
                               points)
        print('%s: %s' % (name, 'engine' if stored else 'FDTD and engine'), file=sys.stderr)
        fdtd = (stored[name]['fdtd'] if stored
                else wc.fdtd_levels(args.build, scene, tmp, file, source, points))
        results[name] = {'fdtd': fdtd,
                         'engine': wc.engine_levels(args.build, scene, tmp, file, source, points)}
    return results


def table(results):
    lines = ['| configuration | receiver | FDTD 63 / 125 Hz | engine direct | engine early '
             '(direct + reflections) | engine - FDTD |', '|---|---|---|---|---|---|']
    for angle in ANGLES:
        r = results[name_of(angle)]
        for k, (_, what) in enumerate(RECEIVERS):
            f, e = r['fdtd'][k], r['engine'][k]
            lines.append('| %s | %s | %.1f / %.1f | %.1f / %.1f | %.1f / %.1f | %+.1f / %+.1f |' % (
                name_of(angle), what, f[0], f[1], e[0][0], e[1][0], e[0][1], e[1][1],
                e[0][1] - f[0], e[1][1] - f[1]))
    return '\n'.join(lines)


def check(results):
    failures = []
    for angle in CHECKED_ANGLES:
        r = results[name_of(angle)]
        for k, (_, what) in enumerate(RECEIVERS):
            if what not in ON_AXIS:
                continue
            for i, f in enumerate(OCTAVES):
                d = r['engine'][k][i][1] - r['fdtd'][k][i]
                judge(d, TOLERANCE_DB, '%s, %s, %.0f Hz: engine - FDTD' % (name_of(angle), what, f),
                      failures)
    return failures


def judge(d, tolerance, what, failures):
    """Prints one checked cell (ok or FAIL, `what`, d in dB); d joins failures beyond
    tolerance."""
    ok = abs(d) <= tolerance
    print('%s %s %+.1f dB' % ('ok  ' if ok else 'FAIL', what, d))
    if not ok:
        failures.append(d)


def leaf_effect(results, angle, k, i, which):
    """What the leaf at `angle` takes away beside the doorway at receiver k, octave i (dB):
    its early level less the open doorway's, `which` 'fdtd' or 'engine'."""
    def level(r):
        return r['fdtd'][k][i] if which == 'fdtd' else r['engine'][k][i][1]
    return (level(results[name_of(angle, True)]) - level(results[name_of(None, True)]))


def beside_table(results):
    lines = ['| configuration | receiver | FDTD 63 / 125 Hz | engine early | engine - FDTD | '
             'leaf - open, FDTD | leaf - open, engine |', '|---|---|---|---|---|---|---|']
    for angle in BESIDE_ANGLES:
        r = results[name_of(angle, True)]
        for k, (_, what) in enumerate(BESIDE_RECEIVERS):
            f = r['fdtd'][k]
            e = [r['engine'][k][i][1] for i in range(len(OCTAVES))]
            effect = ('— | —' if angle is None else '%+.1f / %+.1f | %+.1f / %+.1f' % tuple(
                leaf_effect(results, angle, k, i, w) for w in ('fdtd', 'engine')
                for i in range(len(OCTAVES))))
            lines.append('| %s | %s | %.1f / %.1f | %.1f / %.1f | %+.1f / %+.1f | %s |' % (
                name_of(angle), what, f[0], f[1], e[0], e[1], e[0] - f[0], e[1] - f[1], effect))
    return '\n'.join(lines)


def beside_check(results):
    failures = []
    for angle in BESIDE_ANGLES[1:]:
        for k, (_, what) in enumerate(BESIDE_RECEIVERS):
            for i, f in enumerate(OCTAVES):
                d = (leaf_effect(results, angle, k, i, 'engine') -
                     leaf_effect(results, angle, k, i, 'fdtd'))
                judge(d, LEAF_TOLERANCE_DB, "beside, %s, %s, %.0f Hz: the leaf's effect, "
                      'engine - FDTD' % (name_of(angle), what, f), failures)
    return failures


def plot_set(axes_row, results, angles, receivers, beside):
    labels = [name_of(a) for a in angles]
    x = np.arange(len(labels))
    for i, (ax, f) in enumerate(zip(axes_row, OCTAVES)):
        for k, (_, what) in enumerate(receivers):
            fd = [results[name_of(a, beside)]['fdtd'][k][i] for a in angles]
            en = [results[name_of(a, beside)]['engine'][k][i][1] for a in angles]
            line, = ax.plot(x, fd, 'o-', label='%s, FDTD' % what)
            ax.plot(x, en, 's--', color=line.get_color(), label='%s, engine' % what)
        ax.set_xticks(x)
        ax.set_xticklabels(labels, rotation=30)
        ax.set_title('%s, %.0f Hz octave' % ('beside the doorway' if beside else 'in front',
                                              f))
        ax.grid(alpha=0.3)
    axes_row[0].set_ylabel('early level re free field (dB)')
    axes_row[1].legend(fontsize=6, ncol=2)


def plot(results, path):
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(2, 2, figsize=(11, 8.4))
    plot_set(axes[0], results, ANGLES, RECEIVERS, False)
    plot_set(axes[1], results, BESIDE_ANGLES, BESIDE_RECEIVERS, True)
    fig.suptitle('A doorway with its leaf ajar: the engine (dashed) against dpc-wave FDTD (solid)')
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main():
    args = wc.parse_args(__doc__.split('\n')[0], 'door-wave', 'fail unless the axis cells and '
                         "the leaf's effect beside the doorway hold")
    names = [name_of(a) for a in ANGLES] + [name_of(a, True) for a in BESIDE_ANGLES]
    stored = wc.stored_levels(args.json, names, 'door_wave') if args.engine_only else None
    with tempfile.TemporaryDirectory() as tmp:
        results = run_set(args, stored, tmp, ANGLES, False)
        results.update(run_set(args, stored, tmp, BESIDE_ANGLES, True))
    print(table(results))
    print()
    print(beside_table(results))
    if not args.engine_only:
        wc.write_json(results, args.json)
    if args.plot:
        plot(results, args.plot)
    if args.check:
        failures = check(results) + beside_check(results)
        if failures:
            sys.exit('door_wave: %d cells beyond their tolerance' % len(failures))
        print('door_wave: OK')


if __name__ == '__main__':
    main()
