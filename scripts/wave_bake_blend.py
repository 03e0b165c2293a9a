#!/usr/bin/env python3
"""Why baked playback blends the probes' wave bands with the late response's weights instead of
taking the nearest probe's (docs/wave.md, "In the bake"): bakes the room of tests/wave/wave_bake_test.py (4.0 x 2.6 x
3.0 m, alpha 0.2, wave band to 250 Hz, probes on a 1 m grid at 1.6 m), simulates the band with
dpc-wave at listeners halfway between four probes (the worst case: equal weights), and prints
per third octave (31.5-125 Hz) the level of the nearest probe's band and of the four probes'
inverse-distance blend (what the ray band's energies get) against the band simulated at the
listener.

    scripts/wave_bake_blend.py BUILD_DIR
Needs NumPy and h5py.
"""
import json
import os
import subprocess
import sys
import tempfile

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, '..', 'tests', 'wave'))
import wave_bake_test as t  # noqa: E402
from validate_ir import read_wav  # noqa: E402

CENTRES = [31.5, 40, 50, 63, 80, 100, 125]
LISTENERS = [(2.0, 1.6, 1.0), (1.0, 1.6, 2.0), (3.0, 1.6, 2.0), (2.0, 1.6, 2.0)]


def main():
    build = sys.argv[1]
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, 'blend.h5')
        t.bake(build, t.room(tmp, 'blend'), path, '--quiet')
        with h5py.File(path, 'r') as f:
            probes, band = f['probes/position'][:], f['wave/band'][0]
        scene = t.room(tmp, 'blend_at', listeners=LISTENERS)
        out = os.path.join(tmp, 'at.wav')
        subprocess.run([t.tool(build, 'dpc-wave'), scene, '--out', out], check=True,
                       capture_output=True)
        fs, at = read_wav(out)
        nearest_err, blend_err = [], []
        for k, x in enumerate(LISTENERS):
            d = np.linalg.norm(probes - np.array(x), axis=1)
            four = np.argsort(d)[:4]
            w = 1 / d[four] ** 2
            blend = np.sum((w / w.sum())[:, None] * band[four], axis=0)
            truth = t.third_levels(at[:, k], fs, CENTRES)
            nearest_err.append(t.third_levels(band[four[0]], fs, CENTRES) - truth)
            blend_err.append(t.third_levels(blend, fs, CENTRES) - truth)
        for name, err in (('nearest probe', nearest_err), ('4-probe blend', blend_err)):
            err = np.array(err)
            print('%s minus simulated at the listener, dB, per third %s Hz:' % (name, CENTRES))
            for k, row in enumerate(err):
                print('  %s: %s' % (LISTENERS[k], ' '.join('%+5.1f' % v for v in row)))
            print('  mean %+.1f dB, mean |error| %.1f dB, largest |error| %.1f dB' %
                  (err.mean(), np.abs(err).mean(), np.abs(err).max()))


if __name__ == '__main__':
    main()
