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
              1/(4 pi r) within 0.5 dB (the window cuts the high-pass's tail), the levels
              follow 1/r within 0.2 dB of each other, and the delay is r/c within the
              scheme's phase-speed error there (0.3 % along the axis, docs/wave.md) plus 0.15
              of a time step (receivers interpolate between nodes, and the window's cut of
              the high-pass's tail moves the phase: about 50 us at 62.5 Hz).

    wave_test.py BUILD_DIR [modes|free_field ...]
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
        level = abs(spec / pulse) * 4 * np.pi * r
        delay = -np.angle(spec / pulse * np.exp(2j * np.pi * f * r / C)) / (2 * np.pi * f) + r / C
        axis = 'axis' if d[1] == 0 else 'diagonal'
        print('free field %s r %.1f m: level x 4 pi r %.4f (%+.2f dB)  delay %.6f s (r/c %.6f, '
              '%+.1f us)' % (axis, r, level, 20 * np.log10(level), delay, r / C,
                             1e6 * (delay - r / C)))
        check(abs(20 * np.log10(level)) <= 0.5, 'free field %s r %.1f: level 1/(4 pi r)' % (axis, r))
        tol = 0.003 * r / C + 0.15 * step
        check(abs(delay - r / C) <= tol, 'free field %s r %.1f: delay within %.0f us' %
              (axis, r, 1e6 * tol))
        levels.append(level)
    spread = 20 * np.log10(max(levels) / min(levels))
    check(spread <= 0.2, 'free field: 1/r within 0.2 dB (spread %.3f dB)' % spread)


def main():
    build = sys.argv[1]
    which = sys.argv[2:] or ['modes', 'free_field']
    with tempfile.TemporaryDirectory() as tmp:
        for name in which:
            {'modes': modes, 'free_field': free_field}[name](build, tmp)
    print('%d check(s) failed' % len(failures) if failures else 'all checks hold')
    return 1 if failures else 0


if __name__ == '__main__':
    sys.exit(main())
