#!/usr/bin/python3
"""Fresnel-Kirchhoff check: can a door's gap at the jamb be louder than the open doorway?

A listener beside a doorway, in the shadow of its jamb, hears the open doorway as what is left
of the aperture's Fresnel zones after they cancel (the edge's diffracted wave). A strip a few
centimetres wide at the jamb is not cancelled by the rest: Kirchhoff's integral over the strip
alone can exceed the one over the whole aperture. This script integrates both across a thin
screen (the plane of the wall) in 2-D (x across the wall, z along it); the doorway's height
gives both apertures the same stationary-phase factor, which cancels in their ratio. Each gap
transmits fully (tau = 1: the slit model's transmission is near 1 for a 20 mm gap at 8 kHz).

Prints, per octave, the open doorway and the gaps alone re the free field (dB), averaged in
energy over 25 frequencies per octave. Defaults: the held-out sweep's listener beside the
doorway (docs/validation.md, "A held-out door sweep").

Usage: /usr/bin/python3 scripts/jamb_strip_kirchhoff.py [--gap 0.02] [--half-width 0.45]
       [--source -2 -1] [--listener 2 -1]
"""
import argparse

import numpy as np

SPEED_OF_SOUND = 343.2  # m/s, dry air at 20 C


def aperture_field(k, source, listener, z0, z1, points=20000):
    """Kirchhoff's integral over z in [z0, z1] of the screen x = 0 (2-D, obliquity (cos + cos)/2)."""
    z = np.linspace(z0, z1, points)
    r1 = np.hypot(-source[0], z - source[1])
    r2 = np.hypot(listener[0], listener[1] - z)
    obliquity = 0.5 * (-source[0] / r1 + listener[0] / r2)
    return np.sum(np.exp(-1j * k * (r1 + r2)) / np.sqrt(r1 * r2) * obliquity) * (z[1] - z[0])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--gap', type=float, default=0.02, help='gap width at each jamb, m')
    ap.add_argument('--half-width', type=float, default=0.45, help="doorway's half width, m")
    ap.add_argument('--source', type=float, nargs=2, default=[-2.0, -1.0], help='x z, m')
    ap.add_argument('--listener', type=float, nargs=2, default=[2.0, -1.0], help='x z, m')
    a = ap.parse_args()
    h, g = a.half_width, a.gap
    print('octave  open doorway  gaps alone  (dB re free field)')
    for centre in (1000, 2000, 4000, 8000):
        opened, gaps = [], []
        for f in centre * 2.0 ** np.linspace(-0.5, 0.5, 25):
            k = 2 * np.pi * f / SPEED_OF_SOUND
            free = abs(aperture_field(k, a.source, a.listener, -30, 30, 600000)) ** 2
            opened.append(abs(aperture_field(k, a.source, a.listener, -h, h)) ** 2 / free)
            gaps.append((abs(aperture_field(k, a.source, a.listener, -h, -h + g)) ** 2 +
                         abs(aperture_field(k, a.source, a.listener, h - g, h)) ** 2) / free)
        print('%5d Hz  %8.1f  %10.1f' % (centre, 10 * np.log10(np.mean(opened)),
                                          10 * np.log10(np.mean(gaps))))


if __name__ == '__main__':
    main()
