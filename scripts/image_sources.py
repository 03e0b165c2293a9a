"""Exact image sources of a rectangular room (Allen & Berkley 1979 lattice), for validation.

A box [0, Lx] x [0, Ly] x [0, Lz] with one absorption coefficient a on every surface and every
band: the image of the source for lattice index (n, p) per axis sits at (1 - 2p) s + 2 n L
and has |n - p| + |n| reflections on that axis. Each image contributes energy
(1 - a)^order / (4 pi d^2) (intensity relative to source power, dpc's unit) at delay d / c.
"""
import math

import numpy as np


def image_sources(size, source, listener, alpha, reach, c=343.0):
    """Arrays (delay_s, energy, order) of every image source within `reach` metres, sorted by
    delay; the direct sound is the entry of order 0."""
    size, src, lis = np.asarray(size, float), np.asarray(source, float), np.asarray(listener, float)
    axes = []
    for k in range(3):
        nmax = int(math.ceil(reach / (2 * size[k]))) + 1
        coords, counts = [], []
        for n in range(-nmax, nmax + 1):
            for p in (0, 1):
                coords.append((1 - 2 * p) * src[k] + 2 * n * size[k])
                counts.append(abs(n - p) + abs(n))
        axes.append((np.array(coords) - lis[k], np.array(counts)))
    (dx, nx), (dy, ny), (dz, nz) = axes
    delays, energies, orders = [], [], []
    for i in range(len(dx)):
        if abs(dx[i]) > reach:
            continue
        d2 = dx[i] ** 2 + dy[:, None] ** 2 + dz[None, :] ** 2
        order = nx[i] + ny[:, None] + nz[None, :]
        d = np.sqrt(d2)
        keep = d < reach
        delays.append(d[keep] / c)
        energies.append(np.power(1.0 - alpha, order[keep]) / (4 * np.pi * d2[keep]))
        orders.append(order[keep])
    delay, energy, order = (np.concatenate(x) for x in (delays, energies, orders))
    sort = np.argsort(delay, kind='stable')
    return delay[sort], energy[sort], order[sort]


def energy_response(size, source, listener, alpha, length_s, bin_s=1e-3, c=343.0):
    """(direct delay s, direct energy, per-bin reflected energy) of the specular box."""
    delay, energy, order = image_sources(size, source, listener, alpha, c * length_s, c)
    direct = order == 0
    nbins = int(round(length_s / bin_s))
    bins = np.zeros(nbins)
    np.add.at(bins, np.minimum((delay[~direct] / bin_s).astype(int), nbins - 1), energy[~direct])
    return float(delay[direct][0]), float(energy[direct][0]), bins
