#!/usr/bin/python3
"""Per-band energy decay curves (Schroeder EDC) of an energy response and of a synthesised IR.

Usage: scripts/plot_decay.py ER.csv IR.wav [--source N] [-o decay.png]

ER.csv comes from `dpc-demo ... --er-out ER.csv`, IR.wav from `--ir-out IR.wav` of the same run
(mono output: channel N+1 is source N). The energy response's EDC is drawn from its 1 ms bins
with the direct sound added to its bin; the IR is split into octave bands by the ISO 3382-1
analysis filters that dpc-analyze uses and the synthesiser matches its band energies on
(engine/octave_filter.h: IEC 61260-1 6th-order Butterworth band-pass, bilinear with both edges
fc * 2^(+-1/2) prewarped; here scipy.signal.butter(3, edges, 'bandpass', fs), the same
design), causal, squared and backward-integrated. Both curves start at the IR's onset (first
sample within 20 dB of the peak). Bands whose upper edge reaches Nyquist are left empty.
"""
import argparse
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from plot_render import read_wav  # noqa: E402

CENTRES = [1000.0 * 2.0 ** (b - 4) for b in range(8)]
LABELS = ["63", "125", "250", "500", "1k", "2k", "4k", "8k"]


def octave_band(x, fs, b):
    """x through the ISO 3382-1 octave filter of band b (None above Nyquist)."""
    from scipy.signal import butter, sosfilt
    lo, hi = CENTRES[b] / np.sqrt(2), CENTRES[b] * np.sqrt(2)
    if hi >= fs / 2:
        return None
    return sosfilt(butter(3, [lo, hi], btype="bandpass", fs=fs, output="sos"), x)


def read_er(path, source):
    direct, bins = None, []
    with open(path) as fh:
        rows = [r for r in csv.reader(line for line in fh if not line.startswith("#"))]
    for r in rows[1:]:
        if int(r[0]) != source:
            continue
        if r[1] == "direct":
            direct = (float(r[2]), np.array([float(v) for v in r[3:]]))
        else:
            bins.append([float(v) for v in r[3:]])
    e = np.array(bins)
    if direct is not None:
        e[int(direct[0] / 1e-3)] += direct[1]
    return e


def edc_db(e):
    tail = np.cumsum(e[::-1])[::-1]
    return 10 * np.log10(np.maximum(tail / tail[0], 1e-12))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("er")
    ap.add_argument("ir")
    ap.add_argument("--source", type=int, default=0)
    ap.add_argument("-o", "--output", default="decay.png")
    a = ap.parse_args()
    er = read_er(a.er, a.source)
    x, fs = read_wav(a.ir)
    ir = x[a.source]
    onset = int(np.argmax(ir ** 2 >= 0.01 * np.max(ir ** 2)))
    fig, axes = plt.subplots(2, 4, figsize=(14, 6), sharex=True, sharey=True,
                             constrained_layout=True)
    k0 = int(onset / fs / 1e-3)
    for b, ax in enumerate(axes.flat):
        band = octave_band(ir, fs, b)
        t_ir = np.arange(len(ir) - onset) / fs
        if band is not None:
            ax.plot(t_ir, edc_db(band[onset:] ** 2), label="synthesised IR", lw=1.5)
        t_er = np.arange(len(er) - k0) * 1e-3
        ax.plot(t_er, edc_db(er[k0:, b]), "--", label="energy response", lw=1.5)
        ax.set(title=f"{LABELS[b]} Hz", ylim=(-60, 2), xlim=(0, t_er[-1]))
        ax.grid(alpha=0.3)
        if b % 4 == 0:
            ax.set_ylabel("EDC (dB)")
        if b >= 4:
            ax.set_xlabel("time after onset (s)")
    axes.flat[0].legend(fontsize=8)
    fig.suptitle(f"Schroeder decay per octave band: {a.er} vs {a.ir}")
    fig.savefig(a.output, dpi=90)
    print(f"wrote {a.output}")


if __name__ == "__main__":
    main()
