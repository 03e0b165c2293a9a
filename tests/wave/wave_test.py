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

  cli         dpc-wave's bad input: one line naming the flag, exit status 1, no file written.

    wave_test.py BUILD_DIR [modes|free_field|join|cli ...]
Exit status 0 when every check holds; prints what it measured.
"""
import json
import os
import subprocess
import sys
import tempfile

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
             ([box, '--out', box], '--out'),
             ([box, '--out', out, '--listener', 'nobody'], '--listener')]
    for args, field in cases:
        before = open(box).read()
        done = subprocess.run([exe] + args, capture_output=True, text=True)
        lines = done.stderr.strip().splitlines()
        check(done.returncode == 1 and len(lines) == 1 and field in lines[0] and
              not os.path.exists(out) and open(box).read() == before,
              'dpc-wave %s: one line naming %s, status 1, no file (%r)' %
              (' '.join(args[1:]), field, lines[:2]))


def main():
    build = sys.argv[1]
    which = sys.argv[2:] or ['modes', 'free_field', 'join', 'cli']
    with tempfile.TemporaryDirectory() as tmp:
        for name in which:
            {'modes': modes, 'free_field': free_field, 'join': join, 'cli': cli}[name](build, tmp)
    print('%d check(s) failed' % len(failures) if failures else 'all checks hold')
    return 1 if failures else 0


if __name__ == '__main__':
    sys.exit(main())
