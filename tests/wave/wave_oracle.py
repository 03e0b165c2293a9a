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


def write_mesh(folder, name, quads, absorption, sources, listeners, wave, ir_length=0.2):
    """A scene of quads ({material: [(p0, p1, p2, p3), ...]}, each material's absorption the
    same in every octave band, `absorption`: {material: alpha}); writes NAME.obj and
    NAME.json, returns the scene's path."""
    with open(os.path.join(folder, name + '.obj'), 'w') as f:
        count = 0
        for material, items in quads.items():
            f.write('usemtl %s\n' % material)
            for q in items:
                for p in q:
                    f.write('v %r %r %r\n' % tuple(float(c) for c in p))
                f.write('f %d %d %d\nf %d %d %d\n' % (count + 1, count + 2, count + 3,
                                                      count + 1, count + 3, count + 4))
                count += 4
    scene = {
        'mesh': name + '.obj',
        'materials': {m: {'absorption': [absorption[m]] * 8, 'scattering': 0.1} for m in quads},
        'sources': [{'name': 's%d' % i, 'position': list(p)} for i, p in enumerate(sources)],
        'listeners': [{'name': 'l%d' % i, 'position': list(p)} for i, p in enumerate(listeners)],
        'propagation': {'ir_length': ir_length, 'speed_of_sound': 343.0},
        'wave': dict(wave, enabled=True),
    }
    path = os.path.join(folder, name + '.json')
    with open(path, 'w') as f:
        json.dump(scene, f, indent=1)
    return path


def wedge_diffraction_ir(wedge, rs, theta_s, zs, rr, theta_r, zr, c, fs, t_end, fine=200000,
                         sharp=0.002):
    """The Biot-Tolstoy impulse response of the diffraction by an infinite rigid wedge of
    exterior angle `wedge` (2 pi: a thin half-plane), source and receiver in cylindrical
    coordinates about the edge (distance r, angle theta from one face, position z along the
    edge), in the convention where the direct sound is delta(t - R/c) / R:

        h(t) = -(c nu / (2 pi)) sum_{4 terms} sin(nu phi) / (cosh(nu eta) - cos(nu phi))
               / (rs rr sinh eta),   t > tau0 = sqrt((rs + rr)^2 + (zr - zs)^2) / c,
        cosh eta = (c^2 t^2 - rs^2 - rr^2 - (zr - zs)^2) / (2 rs rr),
        nu = pi / wedge,  phi = pi +- theta_s +- theta_r

    (M. A. Biot and I. Tolstoy, JASA 29(3), 1957; in this form U. P. Svensson, R. I. Fred and
    J. Vanderkooy, JASA 106(5), 1999: the edge as a line of secondary sources has c nu / (4 pi)
    per half of the edge, and each time t > tau0 is reached from both halves). The scale is
    checked by the test itself: across the shadow boundary the diffraction jumps by the direct
    sound it replaces, so the total field is continuous (screen_oracle_check).

    Returned sampled at fs, band-limited: h is integrated in u = sqrt(t - tau0) (h dt =
    2 u h du, finite at u = 0, where h grows as 1 / sqrt(t - tau0)); its first `sharp` seconds,
    where it changes fastest, as areas over 1/32 of a sample each placed at its centre by a
    windowed sinc (dirac_ir's), so no part of it is moved to the sample grid; the rest as its
    area over each sample interval [(n - 1/2) / fs, (n + 1/2) / fs)."""
    nu = np.pi / wedge
    dz2 = (zr - zs) ** 2
    tau0 = np.sqrt((rs + rr) ** 2 + dz2) / c
    n = int(np.ceil(t_end * fs))
    out = np.zeros(n)
    if tau0 >= t_end:
        return out
    u = np.linspace(0.0, np.sqrt(t_end - tau0), fine + 1)[1:]
    t = tau0 + u * u
    cosh_eta = (c * c * t * t - rs * rs - rr * rr - dz2) / (2 * rs * rr)
    eta = np.arccosh(np.maximum(cosh_eta, 1.0))
    # sinh(eta) from its definition, without the cancellation near eta = 0.
    sinh_eta = np.sqrt(np.maximum(cosh_eta * cosh_eta - 1.0, 1e-300))
    beta = 0.0
    for sa in (1, -1):
        for sb in (1, -1):
            phi = np.pi + sa * theta_s + sb * theta_r
            beta = beta + np.sin(nu * phi) / (np.cosh(nu * eta) - np.cos(nu * phi))
    g = -(c * nu / (2 * np.pi)) * beta / (rs * rr * sinh_eta) * 2 * u
    # Cumulative integral over u (trapezoids; g at u = 0 from its limit, the first value).
    du = u[1] - u[0]
    cum = np.concatenate([[0.0], np.cumsum((np.concatenate([[g[0]], g[:-1]]) + g) / 2 * du)])
    uu = np.concatenate([[0.0], u])

    def integral(times):
        return np.interp(np.sqrt(np.maximum(times - tau0, 0.0)), uu, cum)

    t1 = min(tau0 + sharp, t_end)
    edges = (np.arange(n + 1) - 0.5) / fs
    out += np.diff(integral(np.maximum(edges, t1)))
    fine_edges = np.linspace(tau0, t1, int(np.ceil((t1 - tau0) * 32 * fs)) + 1)
    areas = np.diff(integral(fine_edges))
    centres = (fine_edges[1:] + fine_edges[:-1]) / 2
    out += dirac_ir(centres, areas, fs, t_end)
    return out


def dirac_ir(delay, amplitude, fs, t_end):
    """amplitude delta(t - delay) sampled at n / fs with the delay kept exactly: a fractional
    delay by a band-limited (Hann-windowed sinc, 64 taps) kernel. delay and amplitude may be
    arrays (a sum of Diracs)."""
    n = int(np.ceil(t_end * fs))
    out = np.zeros(n)
    centre = np.atleast_1d(np.asarray(delay, float) * fs)
    amplitude = np.broadcast_to(np.asarray(amplitude, float), centre.shape)
    k = np.floor(centre)[:, None] + np.arange(-31, 33)[None, :]
    x = k - centre[:, None]
    w = 0.5 + 0.5 * np.cos(np.pi * x / 33)
    values = amplitude[:, None] * np.sinc(x) * w
    keep = (k >= 0) & (k < n)
    np.add.at(out, k[keep].astype(int), values[keep])
    return out


def screen_ir(source, receiver, plane_x, screens, c, fs, t_end):
    """The impulse response (direct sound 1/R convention) of a point source by thin rigid
    screens in the plane x = plane_x, each the strip lo < y < hi across all z, to first order
    in diffraction: the direct sound where the straight path passes no screen, the reflection
    from the screens where the path from the source's image (mirrored in the plane) meets the
    plane on a screen with source and receiver on the same side, and each finite edge's
    Biot-Tolstoy diffraction as if that edge's half-plane stood alone (wedge_diffraction_ir,
    exterior angle 2 pi; a bound at +-inf or beyond |y| = 1e6 is no edge). For one screen
    (-inf, e) this is the exact solution of the half-plane; for a slit it leaves out the
    waves diffracted from one edge to the other. Returns (ir, earliest arrival s)."""
    source, receiver = np.asarray(source, float), np.asarray(receiver, float)

    def crossing(a, b):
        """y where the segment a-b crosses the plane, or None."""
        da, db = a[0] - plane_x, b[0] - plane_x
        if da * db >= 0:
            return None
        return a[1] + (b[1] - a[1]) * da / (da - db)

    def on_screen(y):
        return any(lo < y < hi for lo, hi in screens)

    arrivals = []
    n = int(np.ceil(t_end * fs))
    ir = np.zeros(n)
    y = crossing(source, receiver)
    if y is None or not on_screen(y):
        d = float(np.linalg.norm(receiver - source))
        ir += dirac_ir(d / c, 1.0 / d, fs, t_end)
        arrivals.append(d / c)
    image = source.copy()
    image[0] = 2 * plane_x - source[0]
    y = crossing(image, receiver)
    if y is not None and on_screen(y):
        d = float(np.linalg.norm(receiver - image))
        ir += dirac_ir(d / c, 1.0 / d, fs, t_end)
        arrivals.append(d / c)
    for lo, hi in screens:
        for edge, below in ((hi, True), (lo, False)):
            if abs(edge) >= 1e6:
                continue
            # Angles about the edge from the face on the source's side (x < plane_x) through
            # the open side to the face on the other side (2 pi): for a screen below its
            # edge the open side is +y, for one above it is -y (mirror y).
            m = 1.0 if below else -1.0

            def cylinder(p):
                dx, dy = p[0] - plane_x, m * (p[1] - edge)
                return np.hypot(dx, dy), np.arctan2(-dx, -dy) % (2 * np.pi), p[2]

            rs, ts, zs = cylinder(source)
            rr, tr, zr = cylinder(receiver)
            ir += wedge_diffraction_ir(2 * np.pi, rs, ts, zs, rr, tr, zr, c, fs, t_end)
            arrivals.append(np.sqrt((rs + rr) ** 2 + (zr - zs) ** 2) / c)
    return ir, min(arrivals)
