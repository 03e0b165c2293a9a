#!/usr/bin/env python3
"""Reads a dpc-bake file with h5py (Debian python3-h5py): the header, the completion mask, one
probe's energy response, its direction (first-order spherical-harmonic energy) and parameters,
and the probe nearest a point.

    examples/python/read_bake.py BAKE.h5 [X Y Z]

The format is docs/bake-format.md; this script checks the parts it uses the way dpc does
(format name, version, completion) and exits 1 with one line otherwise.
"""
import sys

import h5py
import numpy as np


def fail(path, field, problem):
    sys.exit(f'read_bake.py: {path}: {field}: {problem}')


def open_bake(path):
    try:
        f = h5py.File(path, 'r')
    except OSError as e:
        fail(path, '', f'not a readable HDF5 file ({e})')
    if f.attrs.get('format', b'') not in (b'dpc-bake', 'dpc-bake'):
        fail(path, 'format', 'not a dpc-bake file')
    if int(f.attrs.get('version', -1)) not in (5, 6):  # 6: 5 with the wave band (wave/)
        fail(path, 'version', f"{f.attrs.get('version')} is not 5 or 6")
    if int(f.attrs.get('sh_order', -1)) != 1:
        fail(path, 'sh_order', f"{f.attrs.get('sh_order')} is not 1")
    return f


def world_direction(sh):
    """The unit world direction (x, y up, z) of first-order SH energy [4] (ACN W, Y, Z, X in
    the frame of a listener at yaw 0: x = world x, y = world -z, z = world y), and the
    length of the energy vector |(X, Y, Z)| / W (0: isotropic, 1: one plane wave)."""
    w, y, z, x = sh
    v = np.array([x, z, -y])
    n = np.linalg.norm(v)
    return (v / n if n > 0 else v), (n / w if w > 0 else 0.0)


def main():
    if len(sys.argv) not in (2, 5):
        sys.exit(__doc__)
    path = sys.argv[1]
    f = open_bake(path)
    positions = f['probes/position'][:]            # [P, 3] metres
    done = f['probes/done'][:].astype(bool)        # [P]
    bands = f['band_centres_hz'][:]                # [8] Hz
    columns = f.attrs['parameter_columns']
    columns = (columns.decode() if isinstance(columns, bytes) else columns).split(',')
    print(f"{path}: {len(positions)} probes, {done.sum()} done, complete = {f.attrs['complete']}, "
          f"{f['sources/position'].shape[0]} sources, settings hash {f.attrs['settings_hash']:#018x}")
    point = np.array([float(v) for v in sys.argv[2:5]]) if len(sys.argv) == 5 else positions[0]
    candidates = np.where(done)[0]
    if candidates.size == 0:
        fail(path, 'probes/done', 'no probe is stored yet')
    p = candidates[np.argmin(np.linalg.norm(positions[candidates] - point, axis=1))]
    energy = f['energy'][p, 0]                      # [B, 8] 1/m^2 per 1 ms bin, source 0
    params = f['parameters'][p, 0]                  # [9, 7]
    ci = f['parameters_ci95'][p, 0]
    print(f'probe {p} at {positions[p]} m (nearest stored to {point}), source 0:')
    print(f"  direct sound {f['direct/delay_s'][p, 0] * 1e3:.2f} ms; "
          f'total energy per band (1/m^2): {np.round(energy.sum(axis=0), 5)}')
    k = list(bands).index(1000.0)
    print('  1 kHz: ' + ', '.join(f'{c} {params[k, i]:.3g} ± {ci[k, i]:.2g}'
                                  for i, c in enumerate(columns)))
    print(f"  STI {f['sti'][p, 0]:.3f} ± {f['sti_ci95'][p, 0]:.3f}")
    sh = f['sh_energy'][p, 0]                       # [D, 4, 8] 1/m^2 per 10 ms bin
    late = sh[int(0.05 / f.attrs['directional_bin_seconds']):, :, k].sum(axis=0)
    d, r = world_direction(late)
    print(f'  1 kHz after 50 ms: energy flow toward the probe from {np.round(d, 2)} '
          f'(world), |energy vector| / energy {r:.2f}')


if __name__ == '__main__':
    main()
