#!/usr/bin/env python3
"""The wave band (dpc-wave) against analytic acoustics, measured with NumPy alone
(tests/wave/wave_oracle.py):

  modes       a lightly absorbing 5.0 x 3.4 x 2.4 m box (walls alpha 0.01, floor 0.05): the
              first 20 mode frequencies of the simulated IR (matrix pencil) within 1 % of
              (c/2) sqrt((l/Lx)^2 + (m/Ly)^2 + (n/Lz)^2), their decay constants within 10 % of
              the first-order perturbation result for the walls' admittance. The box's modes
              are at least 1.6 Hz apart (5 bandwidths), so each is resolved.
  free_field  a 24 m cube with absorbing walls, the source at its centre, receivers 1.5, 3
              and 6 m away along an axis and 3 and 6 m along a diagonal: at half the maximum
              frequency each direct sound's level over the pulse's (the documented low-pass at
              the maximum frequency and 10 Hz high-pass, their analytic responses) is
              1/(sqrt(4 pi) r) (dpc's IR scale: energy 1/(4 pi r^2)) within 0.5 dB (the window cuts the high-pass's tail), the levels
              follow 1/r within 0.2 dB of each other, and the delay is r/c within the
              scheme's phase-speed error there (0.3 % along the axis, docs/wave.md) plus 0.15
              of a time step (receivers interpolate between nodes, and the window's cut of
              the high-pass's tail moves the phase: about 50 us at 62.5 Hz).

  join        the shipped shoebox (210 m^3, T30 about 1 s) with six listeners and the wave band
              up to 500 Hz (crossover 250 Hz), rendered by dpc-demo --ir-out with and without
              the wave band (same seed) and the band alone by dpc-wave: per receiver, the
              octave bands from 1 kHz up keep the ray-traced IR's energy within 0.05 dB (the
              3rd-order high-pass passes 1 - 4^-6 there), the thirds at 31.5-50 Hz keep the wave
              band's within 0.15 dB (the ray band leaks 5^-6, -42 dB, at 50 Hz); at each third
              from 125 to 500 Hz the receivers' mean level equals the power-complementary mix
              |LP|^2 E_wave + |HP|^2 E_ray of the bands' mean levels within 1 dB (no bump or dip
              at the crossover), and the wave and ray bands' mean levels over those thirds
              agree within 2 dB (the level calibration; the spatial spread of a third's level,
              about 1.3 dB per receiver, averages to 0.3 dB over 42 bands, and the wave band's
              one admittance per material moves its decay time by up to 25 %: 1 dB).

  screen      a thin rigid half-plane (one wall of zero thickness, in a plane between node
              layers, its edge too) in a 24 m cube whose faces absorb, maximum 250 Hz: at seven
              receivers (shadow, lit, source side) the 63 and 125 Hz octave levels in a window
              that ends before any path touching the cube's faces can arrive are those of the
              exact solution, Biot-Tolstoy's edge diffraction plus the direct sound and the
              reflection where they exist (tests/wave/wave_oracle.py screen_ir, the same
              pulse and window), within 1 dB (the issue asks 2). The oracle checks itself
              first: its field is continuous across the shadow and reflection boundaries.
  slit        a 3 m slit (two half-planes in one plane) the same way, against the two edges'
              first-order diffraction plus the geometric terms, within 1 dB.
  screen_controls  the screen check must be able to fail: without the screen, and with its
              edge 4 spacings (0.5 m) low, against the oracle of the screen as placed, some
              octave lies more than 1 dB off.

  walls_on_nodes  a wall and a thin sheet in planes through node centres close the grid: the
              air flooded from the source is the room's volume within the staircase bound.
  unreached   a listener inside a solid, or the source inside it: refused in one line.
  cli         dpc-wave's bad input: one line naming the flag, exit status 1, no file written.

    wave_test.py BUILD_DIR [modes|free_field|join|screen|slit|screen_controls|cli ...]
Exit status 0 when every check holds; prints what it measured.
"""
import json
import signal
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, '..', '..', 'scripts'))
import wave_oracle as oracle  # noqa: E402
from validate_ir import read_wav  # noqa: E402

C = 343.0
failures = []


def check(ok, what):
    print(('ok    ' if ok else 'FAIL  ') + what)
    if not ok:
        failures.append(what)


def run_wave(build, scene, out, seconds):
    cmd = [os.path.join(build, 'apps', 'dpc-wave'), scene, '--out', out, '--seconds', str(seconds),
           '--json']
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit('dpc-wave failed: ' + done.stderr)
    stats = json.loads(done.stdout.strip().splitlines()[-1])
    rate, ir = read_wav(out)
    return rate, ir, stats


def modes(build, tmp):
    size = (5.0, 3.4, 2.4)
    alpha = {w: 0.01 for w in ('x-', 'x+', 'y+', 'z-', 'z+')}
    alpha['y-'] = 0.05  # the floor
    scene = oracle.write_box(tmp, 'modes', size, alpha, [(0.3, 0.3, 0.3)], [(4.6, 3.05, 2.1)],
                             {'max_frequency': 250})
    fs, ir, stats = run_wave(build, scene, os.path.join(tmp, 'modes.wav'), 8.0)
    beta = {w: oracle.admittance(a) for w, a in alpha.items()}
    expected = oracle.box_modes(size, beta, C, 20)
    neighbours = [m[0] for m in oracle.box_modes(size, beta, C, 40)]
    worst_f = worst_d = 0.0
    for f, lmn, delta in expected:
        fm, dm = oracle.mode_near(ir[:, 0], fs, f, neighbours)
        ef, ed = fm / f - 1, dm / delta - 1
        worst_f, worst_d = max(worst_f, abs(ef)), max(worst_d, abs(ed))
        print('mode %s  %.2f Hz: %.2f (%+.2f %%)  decay %.3f 1/s: %.3f (%+.1f %%)' %
              (lmn, f, fm, 100 * ef, delta, dm, 100 * ed))
        check(abs(ef) <= 0.01, 'mode %s frequency within 1 %%' % (lmn,))
        check(abs(ed) <= 0.10, 'mode %s decay within 10 %%' % (lmn,))
    print('modes: worst frequency error %.2f %%, worst decay error %.1f %% (grid %s, %s s)' %
          (100 * worst_f, 100 * worst_d, stats['nodes'], stats['simulate_s']))


def windowed_spectrum(x, fs, start, length, f):
    """The spectrum at f of x[start, start + length) s under a Hann-tapered (Tukey 0.2) window."""
    a, n = int(round(start * fs)), int(round(length * fs))
    seg = x[a:a + n]
    taper = int(0.1 * n)
    w = np.ones(n)
    w[:taper] = 0.5 - 0.5 * np.cos(np.pi * np.arange(taper) / taper)
    w[n - taper:] = w[:taper][::-1]
    t = (a + np.arange(n)) / fs
    return np.sum(seg * w * np.exp(-2j * np.pi * f * t)), np.sum(w) / fs


def free_field(build, tmp):
    fmax, half = 125.0, 24.0 / 2
    centre = np.array([half, half, half])
    dirs = [(np.array([1.0, 0, 0]), r) for r in (1.5, 3.0, 6.0)]
    dirs += [(np.array([1.0, 1, 1]) / np.sqrt(3), r) for r in (3.0, 6.0)]
    points = [tuple(centre + d * r) for d, r in dirs]
    alpha = {w: 1.0 for w in ('x-', 'x+', 'y-', 'y+', 'z-', 'z+')}
    scene = oracle.write_box(tmp, 'free', (24.0, 24.0, 24.0), alpha, [tuple(centre)], points,
                             {'max_frequency': fmax}, ir_length=0.1)
    fs, ir, stats = run_wave(build, scene, os.path.join(tmp, 'free.wav'), 0.1)
    f = fmax / 2
    step = 1.0 / stats['step_rate_hz']
    levels = []
    for k, (d, r) in enumerate(dirs):
        # A window from 4 ms before the expected arrival to 31 ms after: the first reflection
        # comes at least 12 m (35 ms) later.
        spec, _ = windowed_spectrum(ir[:, k], fs, r / C - 0.004, 0.035, f)
        # The pulse dpc-wave documents: a 4th-order Butterworth low-pass at the maximum
        # frequency (at the grid's step rate) and a 2nd-order high-pass at 10 Hz (at fs).
        pulse = (oracle.butterworth_response('low', 4, fmax, stats['step_rate_hz'], f) *
                 oracle.butterworth_response('high', 2, 10.0, fs, f))
        level = abs(spec / pulse) * np.sqrt(4 * np.pi) * r
        delay = -np.angle(spec / pulse * np.exp(2j * np.pi * f * r / C)) / (2 * np.pi * f) + r / C
        axis = 'axis' if d[1] == 0 else 'diagonal'
        print('free field %s r %.1f m: level x sqrt(4 pi) r %.4f (%+.2f dB)  delay %.6f s (r/c %.6f, '
              '%+.1f us)' % (axis, r, level, 20 * np.log10(level), delay, r / C,
                             1e6 * (delay - r / C)))
        check(abs(20 * np.log10(level)) <= 0.5, 'free field %s r %.1f: level 1/(sqrt(4 pi) r)' % (axis, r))
        tol = 0.003 * r / C + 0.15 * step
        check(abs(delay - r / C) <= tol, 'free field %s r %.1f: delay within %.0f us' %
              (axis, r, 1e6 * tol))
        levels.append(level)
    spread = 20 * np.log10(max(levels) / min(levels))
    check(spread <= 0.2, 'free field: 1/r within 0.2 dB (spread %.3f dB)' % spread)


def band_energy(x, fs, lo, hi):
    """Energy of x between lo and hi Hz (rectangular bands of a zero-padded FFT)."""
    spectrum = np.fft.rfft(x, 4 * len(x))
    f = np.fft.rfftfreq(4 * len(x), 1 / fs)
    return float(np.sum(np.abs(spectrum[(f >= lo) & (f < hi)]) ** 2))


def shoebox_listeners(tmp, enabled):
    root = os.path.join(HERE, '..', '..', 'scenes')
    with open(os.path.join(root, 'shoebox.json')) as f:
        scene = json.load(f)
    scene.pop('listener')
    points = [(8.5, 1.6, 1.5), (7.0, 1.2, 5.0), (5.0, 1.7, 2.0), (8.8, 1.0, 5.8), (3.5, 2.2, 5.5),
              (6.0, 1.4, 3.8)]
    scene['listeners'] = [{'name': 'l%d' % i, 'position': list(p), 'radius': 0.5}
                          for i, p in enumerate(points)]
    scene['mesh'] = os.path.abspath(os.path.join(root, 'shoebox.obj'))
    scene['sources'][0]['signal'] = os.path.abspath(os.path.join(root, 'signals', 'speech.wav'))
    scene['propagation'] = {'ir_length': 1.5, 'rays_per_frame': 8192, 'seed': 3}
    scene['wave'] = {'enabled': enabled, 'max_frequency': 500}
    path = os.path.join(tmp, 'shoebox_%s.json' % ('wave' if enabled else 'rays'))
    with open(path, 'w') as f:
        json.dump(scene, f)
    return path, len(points)


def render_irs(build, scene, tmp, name, count):
    demo = os.path.join(build, 'apps', 'dpc-demo')
    done = subprocess.run([demo, scene, '--offline', os.path.join(tmp, name + '.wav'), '--ir-out',
                           os.path.join(tmp, name + '_ir.wav'), '--duration', '1.6', '--quiet'],
                          capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit('dpc-demo failed: ' + done.stderr)
    return [read_wav(os.path.join(tmp, '%s_ir-l%d.wav' % (name, k)))[1][:, 0] for k in range(count)]


def join(build, tmp):
    rays_scene, count = shoebox_listeners(tmp, False)
    wave_scene, _ = shoebox_listeners(tmp, True)
    rays = render_irs(build, rays_scene, tmp, 'rays', count)
    joined = render_irs(build, wave_scene, tmp, 'joined', count)
    fs, band, stats = run_wave(build, rays_scene, os.path.join(tmp, 'band.wav'), 1.5)
    fc = 250.0
    for k in range(count):
        for centre in (1000, 2000, 4000, 8000):
            lo, hi = centre / np.sqrt(2), centre * np.sqrt(2)
            d = 10 * np.log10(band_energy(joined[k], fs, lo, hi) / band_energy(rays[k], fs, lo, hi))
            check(abs(d) <= 0.05, 'join l%d: %d Hz octave as the ray band (%+.3f dB)' % (k, centre, d))
        for centre in (31.5, 40, 50):
            lo, hi = centre * 2 ** (-1 / 6), centre * 2 ** (1 / 6)
            d = 10 * np.log10(band_energy(joined[k], fs, lo, hi) /
                              band_energy(band[:, k], fs, lo, hi))
            check(abs(d) <= 0.15, 'join l%d: %.1f Hz third as the wave band (%+.3f dB)' %
                  (k, centre, d))
    thirds = fc * 2 ** (np.arange(-3, 4) / 3)
    mean = {}
    for name, irs in (('joined', joined), ('rays', rays), ('wave', [band[:, k] for k in range(count)])):
        mean[name] = np.array([np.mean([band_energy(x, fs, f * 2 ** (-1 / 6), f * 2 ** (1 / 6))
                                        for x in irs]) for f in thirds])
    lp = np.array([abs(oracle.butterworth_response('low', 3, fc, fs, f)) ** 2 for f in thirds])
    mix = lp * mean['wave'] + (1 - lp) * mean['rays']
    for f, j, m, w, r in zip(thirds, mean['joined'], mix, mean['wave'], mean['rays']):
        d = 10 * np.log10(j / m)
        print('join third %.0f Hz: joined %.2f dB, mix %.2f dB (wave %.2f, rays %.2f)' %
              (f, 10 * np.log10(j), 10 * np.log10(m), 10 * np.log10(w), 10 * np.log10(r)))
        check(abs(d) <= 1.0, 'join: %.0f Hz third continuous (%+.2f dB from the mix)' % (f, d))
    calibration = 10 * np.log10(np.sum(mean['wave']) / np.sum(mean['rays']))
    check(abs(calibration) <= 2.0, 'join: wave band level as the ray band around the crossover '
          '(%+.2f dB)' % calibration)


# The screen and slit checks (docs/wave.md, "Accuracy, measured"): a 24 m cube whose faces are
# the grid's absorbing edge, a thin rigid screen in the plane x = 12 m from the floor to the
# edge at y = 14 m, across the whole cube along z (so its other edges lie in the absorbing
# faces); the grid spacing 0.125 m puts the screen and its edge on planes between nodes.
SCREEN_SIZE = 24.0
SCREEN_X = 12.0
SCREEN_EDGE = 14.0
SCREEN_SPACING = 0.125
SCREEN_FMAX = 250.0
SCREEN_SOURCE = (9.0, 13.0, 12.0)
SCREEN_RECEIVERS = [  # (position, what it hears)
    ((15.0, 13.5, 12.0), 'shadow, 0.5 m below the edge'),
    ((15.0, 12.0, 12.0), 'shadow, 2 m below'),
    ((15.0, 10.0, 12.0), 'shadow, 4 m below'),
    ((17.0, 12.5, 12.0), 'shadow, 5 m behind'),
    ((14.0, 11.0, 14.5), 'shadow, 2.5 m along the edge'),
    ((15.0, 17.5, 12.0), 'lit behind the screen'),
    ((10.5, 11.0, 12.0), 'source side: direct and reflection'),
]
OCTAVES = (63.0, 125.0)
# The target is 2 dB per band; the check holds 1 dB, as a 2 dB check would not notice
# the edge 4 spacings (0.5 m) off (screen_controls: 1.9 dB at worst). What the voxels leave
# open is the edge's position within its cell: the oracle with the edge half a spacing up
# against half down differs by up to 0.8 dB (screen prints it): +-0.4 dB about the nominal edge.
SCREEN_TOLERANCE_DB = 1.0


def marker_quads(size):
    """Two 1 cm quads in the cube's corners that make the mesh's bounding box the cube."""
    e = 0.01
    return [((0, size, 0), (e, size, 0), (e, size - e, 0), (0, size - e, 0)),
            ((size, 0, size), (size - e, 0, size), (size - e, e, size), (size, e, size))]


def screen_scene(tmp, name, screens, source, receivers):
    """The cube with rigid screens in the plane x = SCREEN_X, each (y_low, y_high) across z."""
    s = SCREEN_SIZE
    quads = {'screen': [((SCREEN_X, lo, 0), (SCREEN_X, hi, 0), (SCREEN_X, hi, s), (SCREEN_X, lo, s))
                        for lo, hi in screens],
             'marker': marker_quads(s)}
    if not screens:
        quads.pop('screen')
    return oracle.write_mesh(tmp, name, quads, {'screen': 0.0, 'marker': 1.0}, [source],
                             receivers, {'max_frequency': SCREEN_FMAX, 'crossover_hz': 100,
                                         'grid_spacing': SCREEN_SPACING}, ir_length=0.1)


def first_wall_path(source, receiver, size):
    """The shortest path from source to receiver that touches a face of the cube [0, size]^3:
    the distance to the receiver from the nearest of the source's images in the faces (every
    wall reflection, and the diffraction by the screen's ends in the faces, arrives no
    earlier)."""
    best = np.inf
    for a in range(3):
        for plane in (0.0, size):
            image = np.array(source, float)
            image[a] = 2 * plane - image[a]
            best = min(best, float(np.linalg.norm(image - np.asarray(receiver))))
    return best


def tukey(n, share=0.2):
    w = np.ones(n)
    taper = int(share / 2 * n)
    w[:taper] = 0.5 - 0.5 * np.cos(np.pi * np.arange(taper) / taper)
    w[n - taper:] = w[:taper][::-1]
    return w


def band_levels(x, fs, centres, fraction=1):
    """Energy of x in the bands of 1/fraction octave at `centres` (rectangular bands of a
    zero-padded FFT, edges at the centre times 2^(+-1/(2 fraction)))."""
    half = 2 ** (1 / (2 * fraction))
    return np.array([band_energy(x, fs, f / half, f * half) for f in centres])


def pulse_filtered(ir, fs, step_rate):
    """ir (1/R convention) as dpc-wave's output: scaled to 1/(sqrt(4 pi) R), through the
    documented pulse (4th-order Butterworth low-pass at the maximum frequency, at the grid's
    step rate) and the 10 Hz 2nd-order high-pass, nothing above half the step rate (the grid
    holds nothing there). Both filters are causal, so the FFT's wrap is kept off by padding."""
    n = 4 * len(ir)
    spectrum = np.fft.rfft(ir, n) / np.sqrt(4 * np.pi)
    f = np.fft.rfftfreq(n, 1 / fs)
    response = np.array([oracle.butterworth_response('low', 4, SCREEN_FMAX, step_rate, x) *
                         oracle.butterworth_response('high', 2, 10.0, fs, x)
                         if 0 < x < step_rate / 2 else 0.0 for x in f])
    return np.fft.irfft(spectrum * response, n)[:len(ir)]


def screen_compare(build, tmp, name, screens, oracle_screens, source, receivers, label,
                   details=None):
    """Simulates the cube with `screens` ((y_low, y_high) strips in the plane x = SCREEN_X)
    and compares each receiver's octave levels in a window with those of the oracle for
    `oracle_screens` (oracle.screen_ir) in the same window: from 4 ms before the first arrival
    to 6 ms before the first path that touches a face of the cube can arrive. Returns the
    differences (dB) per receiver and octave; appends each receiver's numbers and windowed
    signals to `details` when given (scripts/plot_wave_diffraction.py)."""
    points = [p for p, _ in receivers]
    scene = screen_scene(tmp, name, screens, source, points)
    fs, ir, stats = run_wave(build, scene, os.path.join(tmp, name + '.wav'), 0.08)
    print('%s: grid %s nodes, spacing %s m, step rate %d Hz, simulated in %.1f s' %
          (label, stats['nodes'], SCREEN_SPACING, stats['step_rate_hz'], stats['simulate_s']))
    out = []
    for k, (p, what) in enumerate(receivers):
        t_end = first_wall_path(source, p, SCREEN_SIZE) / C - 0.006
        ana, arrival = oracle.screen_ir(source, p, SCREEN_X, oracle_screens, C, fs, t_end)
        ana = pulse_filtered(ana, fs, stats['step_rate_hz'])
        distance = float(np.linalg.norm(np.subtract(p, source)))
        free = pulse_filtered(oracle.dirac_ir(distance / C, 1 / distance, fs, t_end), fs,
                              stats['step_rate_hz'])
        a, b = int(round((arrival - 0.004) * fs)), int(round(t_end * fs))
        a = max(a, 0)
        w = tukey(b - a)
        sim, ref = band_levels(ir[a:b, k] * w, fs, OCTAVES), band_levels(ana[a:b] * w, fs, OCTAVES)
        d = 10 * np.log10(sim / ref)
        # The screen's effect in the oracle: its level over the free field's at that distance
        # (the direct sound alone, in a window as long from 4 ms before it).
        f0 = max(int(round((distance / C - 0.004) * fs)), 0)
        effect = 10 * np.log10(ref / band_levels(free[f0:f0 + b - a] * w, fs, OCTAVES))
        print('%s %-38s window %4.1f-%4.1f ms: oracle %+6.1f %+6.1f dB re free field, '
              'simulated - oracle %+.2f %+.2f dB (63, 125 Hz octaves)'
              % (label, what, 1e3 * a / fs, 1e3 * b / fs, effect[0], effect[1], d[0], d[1]))
        out.append(d)
        if details is not None:
            details.append({'receiver': p, 'what': what, 'window_s': [a / fs, b / fs],
                            'oracle_re_free_db': effect.tolist(), 'difference_db': d.tolist(),
                            'simulated': ir[a:b, k] * w, 'oracle': ana[a:b] * w, 'fs': fs})
    return np.array(out)


def screen_oracle_check():
    """The oracle's own consistency: across the shadow boundary of the half-plane (the
    direct sound appears) and across the reflection boundary (the screen's reflection
    appears) the total field is continuous, so the diffraction term jumps by the geometric
    term exactly (its sign and scale): each side's field extrapolated to the boundary, 63-250
    Hz, within 0.5 % (a wrong scale or sign of the diffraction leaves a jump of 50 % or more)."""
    fs = 48000
    source = np.array(SCREEN_SOURCE)
    edge = np.array([SCREEN_X, SCREEN_EDGE, source[2]])
    screens = [(-np.inf, SCREEN_EDGE)]
    image = source.copy()
    image[0] = 2 * SCREEN_X - source[0]
    for name, start in (('shadow boundary', source), ('reflection boundary', image)):
        # The boundary: the line from the source (or its image in the screen) past the edge,
        # 6 m beyond it.
        direction = (edge - start) / np.linalg.norm(edge - start)
        on = edge + 6.0 * direction
        normal = np.array([-direction[1], direction[0], 0.0])
        # Each side's field extrapolated linearly to the boundary from 1 and 2 cm off it (the
        # geometric terms' own gradient cancels).
        irs = {side: oracle.screen_ir(source, on + side * 0.01 * normal, SCREEN_X, screens, C,
                                      fs, 0.1)[0] for side in (-2, -1, 1, 2)}
        for f in (63.0, 125.0, 250.0):
            kernel = np.exp(-2j * np.pi * f * np.arange(int(0.1 * fs)) / fs)
            spectrum = {side: np.sum(ir * kernel[:len(ir)]) for side, ir in irs.items()}
            h = [2 * spectrum[1] - spectrum[2], 2 * spectrum[-1] - spectrum[-2]]
            jump = abs(h[0] - h[1]) / abs(h[0])
            check(jump <= 0.005, 'oracle: half-plane field continuous across the %s at %.0f Hz '
                  '(%.2f %%)' % (name, f, 100 * jump))


def screen(build, tmp):
    """A thin rigid half-plane: the oracle exact (screen_ir for one edge)."""
    screen_oracle_check()
    d = screen_compare(build, tmp, 'screen', [(0.0, SCREEN_EDGE)], [(-np.inf, SCREEN_EDGE)],
                       SCREEN_SOURCE, SCREEN_RECEIVERS, 'screen')
    for (p, what), row in zip(SCREEN_RECEIVERS, d):
        for f, x in zip(OCTAVES, row):
            check(abs(x) <= SCREEN_TOLERANCE_DB, 'screen %s: %.0f Hz octave as the half-plane '
                  '(%+.2f dB)' % (what, f, x))
    # The voxel edge's uncertainty: the oracle with its edge half a spacing up and down.
    fs = 48000
    for (p, what) in SCREEN_RECEIVERS:
        t_end = first_wall_path(SCREEN_SOURCE, p, SCREEN_SIZE) / C - 0.006
        levels = []
        for e in (SCREEN_EDGE - SCREEN_SPACING / 2, SCREEN_EDGE + SCREEN_SPACING / 2):
            ana, arrival = oracle.screen_ir(SCREEN_SOURCE, p, SCREEN_X, [(-np.inf, e)], C, fs,
                                            t_end)
            a = int(round((arrival - 0.004) * fs))
            levels.append(band_levels(ana[a:] * tukey(len(ana) - a), fs, OCTAVES))
        spread = 10 * np.log10(levels[0] / levels[1])
        print('screen %-38s oracle with the edge 1/2 spacing down over up: %+.2f %+.2f dB' %
              (what, spread[0], spread[1]))


def screen_controls(build, tmp):
    """The screen check must be able to fail: the simulation without the screen, and with
    its edge 4 spacings (0.5 m) lower, each against the oracle of the screen as it should be:
    some receiver's octave must then lie more than SCREEN_TOLERANCE_DB off."""
    for name, screens in (('no screen', []), ('edge 0.5 m lower',
                                              [(0.0, SCREEN_EDGE - 4 * SCREEN_SPACING)])):
        d = screen_compare(build, tmp, 'control', screens, [(-np.inf, SCREEN_EDGE)],
                           SCREEN_SOURCE, SCREEN_RECEIVERS, name)
        worst = float(np.max(np.abs(d)))
        check(worst > SCREEN_TOLERANCE_DB, 'screen control, %s: the check fails (worst %.2f dB '
              'off)' % (name, worst))


SLIT = (12.5, 15.5)
SLIT_SOURCE = (9.0, 14.0, 12.0)
SLIT_RECEIVERS = [
    ((15.0, 14.0, 12.0), 'through the slit, on its axis'),
    ((15.0, 16.5, 12.0), 'through the slit, 2.5 m off axis'),
    ((15.0, 10.5, 12.0), 'shadow of the lower screen'),
    ((15.0, 19.0, 12.0), 'shadow of the upper screen'),
    ((16.0, 8.5, 13.5), 'deep shadow, off the plane'),
    ((10.5, 12.0, 12.0), 'source side: direct and reflection'),
]


def slit(build, tmp):
    """A 3 m slit (two half-planes in one plane, edges at y = 12.5 and 15.5 m) against the
    sum of the two edges' first-order diffraction (Biot-Tolstoy) and the geometric terms."""
    lo, hi = SLIT
    d = screen_compare(build, tmp, 'slit', [(0.0, lo), (hi, SCREEN_SIZE)],
                       [(-np.inf, lo), (hi, np.inf)], SLIT_SOURCE, SLIT_RECEIVERS, 'slit')
    for (p, what), row in zip(SLIT_RECEIVERS, d):
        for f, x in zip(OCTAVES, row):
            check(abs(x) <= SCREEN_TOLERANCE_DB, 'slit %s: %.0f Hz octave as first-order BTM '
                  '(%+.2f dB)' % (what, f, x))

def box_quads(x0, x1, y0, y1, z0, z1):
    """The six faces of a box, normals out."""
    return [((x0, y0, z0), (x0, y0, z1), (x0, y1, z1), (x0, y1, z0)),
            ((x1, y0, z0), (x1, y1, z0), (x1, y1, z1), (x1, y0, z1)),
            ((x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1)),
            ((x0, y1, z0), (x0, y1, z1), (x1, y1, z1), (x1, y1, z0)),
            ((x0, y0, z0), (x0, y1, z0), (x1, y1, z0), (x1, y0, z0)),
            ((x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1))]


def walls_on_nodes(build, tmp):
    """A wall in a plane through node centres closes the grid there as any other wall does.
    The oracle is the geometry: the air the grid floods from the source and the listener is
    the room's volume within the staircase bound (each wall within half a spacing:
    |dV| <= S h / 2 for a room of surface S). Two rooms, each with a wall on node centres
    (the bounding box [0, X] holds an odd number of nodes, so X / 2 is a node centre):
    - an L-shaped room 5 x 5.5 x 2.6 m whose notch (x > 2.5, z > 3) is outside the mesh:
      55.25 m^3 (the whole box, 71.5 m^3, when the notch walls are lost);
    - a 5 x 3 x 4 m box split at x = 2.5 by a sheet of zero thickness, source and listener on
      one side: 30 m^3 (60 when the sheet is lost).
    Each at two spacings: 250 Hz's default (5 m / 37) and 5 m / 39. Whether a ray from a node
    centre loses a surface at its end depends on rounding, so both are tried."""
    L = [((0, 0, 0), (5, 0, 0), (5, 0, 3), (0, 0, 3)), ((0, 0, 3), (2.5, 0, 3), (2.5, 0, 5.5),
                                                        (0, 0, 5.5))]
    floor = L
    ceiling = [tuple((x, 2.6, z) for x, _, z in reversed(q)) for q in L]
    plan = [(0, 0), (5, 0), (5, 3), (2.5, 3), (2.5, 5.5), (0, 5.5)]
    walls = []
    for (xa, za), (xb, zb) in zip(plan, plan[1:] + plan[:1]):
        walls.append(((xa, 0, za), (xa, 2.6, za), (xb, 2.6, zb), (xb, 0, zb)))
    rooms = [('L-shaped room, notch wall at x = 2.5 m', {'walls': floor + ceiling + walls},
              [(4.5, 1.2, 1.0)], [(1.0, 1.5, 5.0)], 55.25, 2 * 21.25 + 21.0 * 2.6),
             ('5 x 3 x 4 m box split by a sheet at x = 2.5 m',
              {'walls': box_quads(0, 5, 0, 3, 0, 4),
               'sheet': [((2.5, 0, 0), (2.5, 3, 0), (2.5, 3, 4), (2.5, 0, 4))]},
              [(1.0, 1.5, 1.0)], [(2.0, 1.2, 3.0)], 30.0, 2 * (7.5 + 10 + 12))]
    for k, (what, quads, sources, listeners, volume, surface) in enumerate(rooms):
        for wave in ({'max_frequency': 250}, {'max_frequency': 250, 'grid_spacing': 5 / 39}):
            h = wave.get('grid_spacing', 5 / 37)
            absorption = {m: 0.1 for m in quads}
            scene = oracle.write_mesh(tmp, 'nodes%d' % k, quads, absorption, sources, listeners,
                                      wave, ir_length=0.1)
            _, _, stats = run_wave(build, scene, os.path.join(tmp, 'nodes%d.wav' % k), 0.01)
            bound = surface * h / 2
            air = stats['air_volume_m3']
            check(abs(air - volume) <= bound, 'walls on node centres, %s, spacing %.4f m: air '
                  '%.2f m^3 against %.2f (staircase bound %.1f)' % (what, h, air, volume, bound))


def unreached(build, tmp):
    """A listener the source's air does not reach is refused, not simulated in air of its own
    (where it heard nothing: an all-zero IR with exit status 0): inside a closed 0.5 m solid
    slab standing in a 6 x 3 x 4 m room, and the source inside it with the listener in the
    room. One line naming the listener and the source, exit status 1, no file."""
    room = {'walls': box_quads(0, 6, 0, 3, 0, 4), 'slab': box_quads(2.5, 3.0, 0.5, 2.5, 1.0, 3.0)}
    inside, air = (2.75, 1.5, 2.0), (1.0, 1.5, 1.0)
    exe = os.path.join(build, 'apps', 'dpc-wave')
    for k, (source, listener) in enumerate(((air, inside), (inside, air))):
        scene = oracle.write_mesh(tmp, 'unreached%d' % k, room, {'walls': 0.1, 'slab': 0.1},
                                  [source], [listener], {'max_frequency': 150}, ir_length=0.1)
        out = os.path.join(tmp, 'unreached%d.wav' % k)
        done = subprocess.run([exe, scene, '--out', out, '--seconds', '0.05'],
                              capture_output=True, text=True)
        lines = done.stderr.strip().splitlines()
        check(done.returncode == 1 and len(lines) == 1 and
              'listeners[0].position: lies in no air the wave grid reaches from '
              'sources[0].position' in lines[0] and not os.path.exists(out),
              'dpc-wave, %s inside a solid: one line naming the listener and the source, '
              'status 1, no file (%r)' % ('listener' if k == 0 else 'source', lines[:2]))


def cli(build, tmp):
    """dpc-wave's bad input: one line naming the flag or field, exit status 1, no file."""
    box = oracle.write_box(tmp, 'cli', (3.0, 2.5, 2.0), {w: 0.1 for w in ('x-', 'x+', 'y-', 'y+',
                           'z-', 'z+')}, [(1.0, 1.0, 1.0)], [(2.0, 1.5, 1.2)], {'max_frequency': 100})
    out = os.path.join(tmp, 'cli_out.wav')
    exe = os.path.join(build, 'apps', 'dpc-wave')
    cases = [([box, '--out', out, '--source', '3'], '--source'),
             ([box, '--out', out, '--max-frequency', '5000'], '--max-frequency'),
             ([box, '--out', out, '--grid-spacing', '2'], '--grid-spacing'),
             ([box, '--out', out, '--seconds', '0'], '--seconds'),
             # In range, but no sample long: it ran the simulation and then blamed --out.
             ([box, '--out', out, '--seconds', '1e-9'],
              '--seconds: 1e-09 s is shorter than one sample'),
             ([box, '--out', box], '--out'),
             ([box, '--out', out, '--listener', 'nobody'], '--listener'),
             ([box, '--out', out, '--source', '-1'], '--source: -1 is not'),
             ([box, '--out', out, '--grid-spacing', '1e-6'], '--grid-spacing: a grid of 1e-06 m'),
             # Held as 0 it would mean "automatic": refused, not quietly replaced.
             ([box, '--out', out, '--grid-spacing', '1e-300'],
              '--grid-spacing: 1e-300 rounds to 0 in single precision'),
             ([box, '--out', '/proc/w.wav'], "--out: folder '/proc' is not writable"),
             ([box, '--out', os.path.join(tmp, 'w.csv')], "names a CSV file, but --out writes WAV")]
    for args, field in cases:
        before = open(box).read()
        done = subprocess.run([exe] + args, capture_output=True, text=True)
        lines = done.stderr.strip().splitlines()
        check(done.returncode == 1 and len(lines) == 1 and field in lines[0] and
              not os.path.exists(out) and open(box).read() == before,
              'dpc-wave %s: one line naming %s, status 1, no file (%r)' %
              (' '.join(args[1:]), field, lines[:2]))


def stop(build, tmp):
    """A stop signal mid-simulation: one line naming it, exit status 128 + n, no file left (the
    process died without a word, a temporary of the WAV left behind)."""
    box = oracle.write_box(tmp, 'stop', (6.0, 4.0, 3.0), {w: 0.1 for w in ('x-', 'x+', 'y-', 'y+',
                           'z-', 'z+')}, [(1.0, 1.0, 1.0)], [(4.0, 2.5, 1.2)], {'max_frequency': 400})
    exe = os.path.join(build, 'apps', 'dpc-wave')
    for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
        out = os.path.join(tmp, 'stop_%d.wav' % sig)
        p = subprocess.Popen([exe, box, '--out', out, '--seconds', '30'], stderr=subprocess.PIPE,
                             text=True)
        line = p.stderr.readline()  # the first progress line: the simulation runs
        p.send_signal(sig)
        err = line + p.stderr.read()
        p.wait()
        left = [f for f in os.listdir(tmp) if f.startswith('stop_%d.wav' % sig)]
        name = signal.Signals(sig).name
        check(p.returncode == 128 + sig and ('interrupted by ' + name) in err and not left,
              'dpc-wave stopped by %s: status %d, a line naming it, no file (%r, %s)' %
              (name, p.returncode, err.strip().splitlines()[-1:], left))
    # Two requests delivered together (a terminal's Ctrl-C and mpirun's, a hangup and the
    # shell's) are one: held while the process is stopped, both arrive at once, and the run
    # stops as for one (a request repeated a quarter of a second later would end it at once).
    p = subprocess.Popen([exe, box, '--out', os.path.join(tmp, 'stop_twice.wav'), '--seconds',
                          '30'], stderr=subprocess.PIPE, text=True)
    p.stderr.readline()
    p.send_signal(signal.SIGSTOP)
    p.send_signal(signal.SIGINT)
    p.send_signal(signal.SIGTERM)
    p.send_signal(signal.SIGCONT)
    err = p.stderr.read()
    p.wait()
    left = [f for f in os.listdir(tmp) if f.startswith('stop_twice.wav')]
    check(p.returncode in (128 + signal.SIGINT, 128 + signal.SIGTERM) and 'interrupted by' in err
          and not left, 'dpc-wave asked twice at once stops as asked once: status %d, files %s' %
          (p.returncode, left))
    # dpc-demo --offline simulates the scene's wave band before its first frame (here minutes):
    # a stop request ends it there, with --quiet too (no progress lines to read, so the signal
    # comes once the run is under way), not only after the band.
    demo = os.path.join(build, 'apps', 'dpc-demo')
    out = os.path.join(tmp, 'stop_demo.wav')
    big = oracle.write_box(tmp, 'stop_big', (6.0, 4.0, 3.0), {w: 0.1 for w in ('x-', 'x+', 'y-',
                           'y+', 'z-', 'z+')}, [(1.0, 1.0, 1.0)], [(4.0, 2.5, 1.2)],
                           {'max_frequency': 1500})  # minutes of grid steps
    with open(big) as f:
        scene = json.load(f)
    scene['sources'][0]['signal'] = os.path.join(HERE, '..', '..', 'scenes', 'signals', 'speech.wav')
    played = os.path.join(tmp, 'stop_played.json')
    with open(played, 'w') as f:
        json.dump(scene, f)
    p = subprocess.Popen([demo, played, '--offline', out, '--duration', '30', '--quiet'],
                         stderr=subprocess.PIPE, text=True)
    time.sleep(3)
    p.send_signal(signal.SIGINT)
    try:
        err = p.communicate(timeout=30)[1]
    except subprocess.TimeoutExpired:
        p.kill()
        err = p.communicate()[1] + ' (still running 30 s after SIGINT)'
    left = [f for f in os.listdir(tmp) if f.startswith('stop_demo.wav')]
    check(p.returncode == 128 + signal.SIGINT and 'interrupted by SIGINT' in err and not left,
          'dpc-demo stopped in its wave band: status %d, a line naming it, no file (%r, %s)' %
          (p.returncode, err.strip().splitlines()[-1:], left))


def main():
    build = sys.argv[1]
    which = sys.argv[2:] or ['modes', 'free_field', 'join', 'cli']
    with tempfile.TemporaryDirectory() as tmp:
        for name in which:
            {'modes': modes, 'free_field': free_field, 'join': join, 'cli': cli, 'stop': stop,
             'screen': screen, 'screen_controls': screen_controls, 'slit': slit,
             'walls_on_nodes': walls_on_nodes, 'unreached': unreached}[name](build, tmp)
    print('%d check(s) failed' % len(failures) if failures else 'all checks hold')
    return 1 if failures else 0


if __name__ == '__main__':
    sys.exit(main())
