#!/usr/bin/env python3
"""What an octave-band measurement reads of noise through an HRIR, against the flat band model.

The spatial synthesiser states each direction's share of an ear's band energy as one number
per octave, w_b (the filter's band energy over the analysed octave, diffuse-field equalised);
a target or an oracle built from those numbers stands for a spectrum that is flat within each
octave, sum_k w_k A_k(f). An HRIR is not flat within an octave (KEMAR's ear-canal rise), so a
band filter reads noise through it differently. This script measures by how much, without any
of dpc's code: the HRIRs from the SOFA file (h5py), resampled to 48 kHz (scipy), the eight
directions of defaultSpatialDirections (synthesis/spatial_directions.cpp) at their nearest
measurements, its own amplitude-complementary octave crossovers (raised cosine, 1/3 octave
wide, as synthesis/band_filters.h's masks are), the per-band diffuse-field equalisation
sum_k A_k / sqrt(kappa_k), and two measurements: scipy's order-3 Butterworth octave filters
(the IEC 61260-1 shape the ISO 3382-1 band analysis uses) and the window levelling's view
weight A_b (M_b^2).

Prints, per band, the mean over directions and ears of 10 log10(reading of the equalised HRIR /
reading of the flat model), and its spread. Usage:
    /usr/bin/python3 scripts/hrir_band_shape.py [--sofa /usr/share/libmysofa/default.sofa]
"""
import argparse

import h5py
import numpy as np
from scipy import signal

FS = 48000
N = 1 << 16
CENTRES = 1000.0 * 2.0 ** np.arange(-4, 4)  # 62.5 Hz .. 8 kHz, exact octave centres


def directions():
    """defaultSpatialDirections: (azimuth, elevation) in degrees, azimuth + to the left."""
    return [(60.0 * i, 0.0) for i in range(6)] + [(0.0, 90.0), (0.0, -40.0)]


def load_hrirs(path):
    f = h5py.File(path, "r")
    ir = np.array(f["Data.IR"])  # measurements x 2 ears x taps
    fs = float(f["Data.SamplingRate"][0])
    pos = np.array(f["SourcePosition"])  # azimuth, elevation (degrees), radius
    out = []
    for az, el in directions():
        a, e = np.radians(pos[:, 0]), np.radians(pos[:, 1])
        v = np.stack([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)], axis=1)
        t = np.array([np.cos(np.radians(el)) * np.cos(np.radians(az)),
                      np.cos(np.radians(el)) * np.sin(np.radians(az)), np.sin(np.radians(el))])
        m = int(np.argmax(v @ t))
        out.append([signal.resample_poly(ir[m, c], 160, 147) if fs == 44100 else ir[m, c]
                    for c in range(2)])
    return out


def crossovers(f):
    """A_k(f), k = 0..7: amplitude-complementary octaves with 1/3-octave raised-cosine edges."""
    lf = np.log2(np.maximum(f, 1e-3) / 1000.0)

    def rise(edge):
        t = np.clip((lf - (edge - 1 / 6)) / (1 / 3), 0.0, 1.0)
        return 0.5 - 0.5 * np.cos(np.pi * t)

    a = []
    for k in range(8):
        c = np.log2(CENTRES[k] / 1000.0)
        x = np.ones_like(f)
        if k > 0:
            x *= rise(c - 0.5)
        if k < 7:
            x *= 1.0 - rise(c + 0.5)
        a.append(x)
    return np.array(a)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--sofa", default="/usr/share/libmysofa/default.sofa")
    args = p.parse_args()
    f = np.fft.rfftfreq(N, 1.0 / FS)
    A = crossovers(f)
    power = [[np.abs(np.fft.rfft(h, N)) ** 2 for h in d] for d in load_hrirs(args.sofa)]
    octave = [(f >= c / np.sqrt(2)) & (f < c * np.sqrt(2)) for c in CENTRES]
    # w_b before equalisation: A_b-weighted mean power over the analysed octave; kappa_b its
    # mean over directions and ears (the diffuse-field equalisation).
    raw = np.array([[[np.sum(A[b][o] * h2[o]) / np.sum(A[b][o]) for b, o in enumerate(octave)]
                     for h2 in d] for d in power])
    kappa = raw.mean(axis=(0, 1))
    eq2 = (A / np.sqrt(kappa)[:, None]).sum(0) ** 2
    iso = []
    for c in CENTRES:
        sos = signal.butter(3, [c / np.sqrt(2), c * np.sqrt(2)], btype="band", fs=FS, output="sos")
        iso.append(np.abs(signal.sosfreqz(sos, worN=f, fs=FS)[1]) ** 2)
    print("band    ISO octave filter: mean (sd) dB    window view A_b: mean (sd) dB")
    for b in range(2, 7):
        rows = {"iso": [], "view": []}
        for d, h2s in enumerate(power):
            for e, h2 in enumerate(h2s):
                flat = ((raw[d, e] / kappa)[:, None] * A).sum(0)
                for name, weight in (("iso", iso[b]), ("view", A[b])):
                    rows[name].append(10 * np.log10(np.sum(weight * h2 * eq2) /
                                                    np.sum(weight * flat)))
        print(f"{int(round(CENTRES[b])):5d}   " + "    ".join(
            f"{np.mean(rows[k]):+.2f} ({np.std(rows[k]):.2f})" for k in ("iso", "view")))


if __name__ == "__main__":
    main()
