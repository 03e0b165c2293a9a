#!/usr/bin/python3
"""Interaural coherence per octave of binaural renders' late parts against an HRTF set's
diffuse field.

Usage: scripts/plot_coherence.py --sofa FILE.sofa LABEL=RENDER.wav ... [-o coherence.png]
                                 [--json coherence.json] [--from 0.15] [--to 0.8]

Each RENDER.wav's first two channels are a binaural impulse response (dpc-demo --ir-out of a
binaural render, or an --offline render of a one-sample click). Its coherence in an octave is
Re sum X_L X_R* / sqrt(sum |X_L|^2 sum |X_R|^2) over the octave's FFT bins of the part from
--from to --to seconds. The diffuse field's is the same sum over every measured HRIR pair of
the SOFA file, each weighted by the solid angle it stands for (the share of 20,000 evenly
spread directions nearest to it), as tests/apps/late_coherence_test.cpp computes it.
"""
import argparse
import json
import os
import sys

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from plot_render import read_wav  # noqa: E402

CENTRES = [125, 250, 500, 1000, 2000, 4000, 8000]


def octave_sums(left, right, fs, n):
    spec_l, spec_r = np.fft.rfft(left, n), np.fft.rfft(right, n)
    f = np.fft.rfftfreq(n, 1.0 / fs)
    out = []
    for fc in CENTRES:
        m = (f >= fc / np.sqrt(2)) & (f < fc * np.sqrt(2))
        out.append((np.sum(np.real(spec_l[m] * np.conj(spec_r[m]))),
                    np.sum(np.abs(spec_l[m]) ** 2), np.sum(np.abs(spec_r[m]) ** 2)))
    return np.array(out)


def fibonacci(count):
    i = np.arange(count)
    z = 1.0 - (2.0 * i + 1.0) / count
    r = np.sqrt(1.0 - z * z)
    phi = i * np.pi * (3.0 - np.sqrt(5.0))
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1)


def diffuse_coherence(path):
    with h5py.File(path, "r") as f:
        ir = np.array(f["Data.IR"])  # M x R x N
        fs = float(np.array(f["Data.SamplingRate"]).ravel()[0])
        pos = np.array(f["SourcePosition"], dtype=float)
        kind = f["SourcePosition"].attrs.get("Type", b"spherical")
    if (kind.decode() if isinstance(kind, bytes) else str(kind)) == "spherical":
        az, el = np.radians(pos[:, 0]), np.radians(pos[:, 1])
        pos = np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)], axis=1)
    pos /= np.linalg.norm(pos, axis=1, keepdims=True)
    nearest = np.argmax(fibonacci(20000) @ pos.T, axis=1)
    weight = np.bincount(nearest, minlength=len(pos)).astype(float)
    total = np.zeros((len(CENTRES), 3))
    for m in np.nonzero(weight)[0]:
        total += weight[m] * octave_sums(ir[m, 0], ir[m, 1], fs, 8192)
    return total[:, 0] / np.sqrt(total[:, 1] * total[:, 2])


def render_coherence(path, start, stop):
    channels, fs = read_wav(path)
    a, b = int(start * fs), int(stop * fs)
    left, right = np.asarray(channels[0][a:b]), np.asarray(channels[1][a:b])
    s = octave_sums(left, right, fs, len(left))
    return s[:, 0] / np.sqrt(s[:, 1] * s[:, 2])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("renders", nargs="+", help="LABEL=RENDER.wav")
    ap.add_argument("--sofa", required=True)
    ap.add_argument("-o", "--output", default="coherence.png")
    ap.add_argument("--json")
    ap.add_argument("--from", dest="start", type=float, default=0.15)
    ap.add_argument("--to", dest="stop", type=float, default=0.8)
    args = ap.parse_args()
    table = {"bands_hz": CENTRES, "hrtf_diffuse_field": diffuse_coherence(args.sofa).tolist()}
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(CENTRES, table["hrtf_diffuse_field"], "k-", lw=2.5, label="HRTF diffuse field")
    for item in args.renders:
        label, path = item.split("=", 1)
        table[label] = render_coherence(path, args.start, args.stop).tolist()
        ax.plot(CENTRES, table[label], "o-", label=label)
    ax.set_xscale("log")
    ax.set_xticks(CENTRES, [f"{c:g}" for c in CENTRES])
    ax.set_ylim(-0.5, 1.05)
    ax.axhline(0, color="grey", lw=0.5)
    ax.set_xlabel("octave band (Hz)")
    ax.set_ylabel(f"interaural coherence, {args.start:g}-{args.stop:g} s")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(args.output, dpi=110)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(table, f, indent=1)
    for key, values in table.items():
        print(f"{key:28s} " + " ".join(f"{v:6.2f}" for v in values))


if __name__ == "__main__":
    main()
