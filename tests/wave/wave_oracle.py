"""Independent instruments for the wave band's tests (NumPy only, nothing from dpc):
box-shaped scenes, the analytic modes of a rectangular room with locally reacting walls, the
Paris statistical absorption, and modal analysis of an impulse response by the matrix pencil.
"""
import itertools
import json
import os

import numpy as np

AXES = 'xyz'


def write_box(folder, name, size, absorption, sources, listeners, wave, ir_length=2.0):
    """A box [0, size] with one material per wall ('x-', 'x+', 'y-', ... -> absorption, the
    same in every octave band); writes NAME.obj and NAME.json, returns the scene's path."""
    lx, ly, lz = size
    v = [(x, y, z) for x in (0, lx) for y in (0, ly) for z in (0, lz)]
    quads = {'x-': (1, 2, 4, 3), 'x+': (5, 7, 8, 6), 'y-': (1, 5, 6, 2), 'y+': (3, 4, 8, 7),
             'z-': (1, 3, 7, 5), 'z+': (2, 6, 8, 4)}
    with open(os.path.join(folder, name + '.obj'), 'w') as f:
        for p in v:
            f.write('v %r %r %r\n' % p)
        for wall, q in quads.items():
            f.write('usemtl %s\n' % wall)
            f.write('f %d %d %d\nf %d %d %d\n' % (q[0], q[1], q[2], q[0], q[2], q[3]))
    scene = {
        'mesh': name + '.obj',
        'materials': {w: {'absorption': [absorption[w]] * 8, 'scattering': 0.1} for w in quads},
        'sources': [{'name': 's%d' % i, 'position': list(p)} for i, p in enumerate(sources)],
        'listeners': [{'name': 'l%d' % i, 'position': list(p)} for i, p in enumerate(listeners)],
        'propagation': {'ir_length': ir_length, 'speed_of_sound': 343.0},
        'wave': dict(wave, enabled=True),
    }
    path = os.path.join(folder, name + '.json')
    with open(path, 'w') as f:
        json.dump(scene, f, indent=1)
    return path


def statistical_absorption(beta, steps=20000):
    """Paris' formula for a locally reacting wall of real normalised admittance beta."""
    if beta <= 0:
        return 0.0
    theta = (np.arange(steps) + 0.5) * (np.pi / 2 / steps)
    zc = np.cos(theta) / beta
    return float(np.sum(4 * zc / (zc + 1) ** 2 * np.sin(2 * theta)) * (np.pi / 2 / steps))


def admittance(alpha):
    """The real admittance in [0, 1/1.567] whose statistical absorption is alpha (bisection)."""
    lo, hi = 0.0, 1 / 1.567
    for _ in range(60):
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if statistical_absorption(mid) < alpha else (lo, mid)
    return (lo + hi) / 2


def box_modes(size, beta, c, count):
    """The first `count` modes (l, m, n) of a box with per-wall admittance beta ('x-' ...):
    [(frequency Hz, (l, m, n), amplitude decay constant 1/s)]. Frequencies
    (c/2) sqrt((l/Lx)^2 + (m/Ly)^2 + (n/Lz)^2); decay from first-order perturbation of the
    rigid mode cos(l pi x / Lx) ...: delta = c / (2 V) sum_walls beta_w S_w eps_w, eps_w = 2
    when the mode varies along the wall's normal axis, 1 when not (Kuttruff, Room Acoustics,
    section 3.4; Morse & Ingard, Theoretical Acoustics, 9.4)."""
    size = np.asarray(size, float)
    volume = size.prod()
    area = [size[1] * size[2], size[0] * size[2], size[0] * size[1]]
    modes = []
    for lmn in itertools.product(range(12), repeat=3):
        if not any(lmn):
            continue
        f = c / 2 * np.sqrt(np.sum((np.array(lmn) / size) ** 2))
        delta = 0.0
        for a in range(3):
            eps = 2.0 if lmn[a] else 1.0
            delta += (beta[AXES[a] + '-'] + beta[AXES[a] + '+']) * area[a] * eps
        modes.append((f, lmn, c / (2 * volume) * delta))
    modes.sort()
    return modes[:count]


def matrix_pencil(y, order):
    """Complex poles z_k of y[n] = sum_k a_k z_k^n from the matrix pencil with total least
    squares (Hua & Sarkar, IEEE TASSP 38(5), 1990)."""
    n = len(y)
    pencil = n // 3
    hankel = np.array([y[i:i + pencil + 1] for i in range(n - pencil)])
    _, _, vh = np.linalg.svd(hankel, full_matrices=False)
    v = vh[:order, :].T
    return np.linalg.eigvals(np.linalg.pinv(v[:-1, :]) @ v[1:, :])


def mode_near(ir, fs, f0, neighbours, half_band=4.0, skip=0.3, length=4.0):
    """(frequency Hz, decay constant 1/s) of the mode of `ir` nearest f0: the IR shifted down
    by f0, band-limited to +-half_band Hz, sampled at 4 half_band Hz from `skip` s for
    `length` s, and its poles by the matrix pencil, the model order one per mode of
    `neighbours` within the band plus two."""
    t = np.arange(len(ir)) / fs
    x = ir * np.exp(-2j * np.pi * f0 * t)
    spectrum = np.fft.fft(x)
    spectrum[np.abs(np.fft.fftfreq(len(x), 1 / fs)) > half_band] = 0
    x = np.fft.ifft(spectrum)
    step = int(fs / (4 * half_band))
    y = x[int(skip * fs):int((skip + length) * fs):step]
    order = 2 + sum(1 for f in neighbours if abs(f - f0) < half_band)
    s = np.log(matrix_pencil(y, order)) * fs / step
    freq, decay = f0 + s.imag / (2 * np.pi), -s.real
    k = int(np.argmin(np.abs(freq - f0) + 1e3 * (decay <= 0)))
    return float(freq[k]), float(decay[k])


def butterworth_response(kind, order, cutoff, fs, f):
    """Complex response at f (Hz) of a digital Butterworth low- or high-pass made by the
    bilinear transform with the cutoff prewarped: the analog prototype's H(j Omega) at
    Omega = 2 fs tan(pi f / fs), Omega_c = 2 fs tan(pi cutoff / fs) (Oppenheim & Schafer,
    7.1.2), poles exp(j pi (2k + N + 1) / (2N))."""
    omega = 2 * fs * np.tan(np.pi * f / fs)
    omega_c = 2 * fs * np.tan(np.pi * cutoff / fs)
    poles = np.exp(1j * np.pi * (2 * np.arange(order) + order + 1) / (2 * order))
    s = 1j * omega / omega_c
    if kind == 'high':
        s = 1 / s
    return 1 / np.prod(s - poles)
