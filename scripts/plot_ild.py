#!/usr/bin/python3
"""Interaural level difference over time of a two-channel render (2-8 kHz, 250 ms windows).

Usage: scripts/plot_ild.py RENDER.wav [-o ild.png] [--events "t:label" ...]
Positive ILD: louder in the left channel.
"""
import argparse
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from plot_render import read_wav  # noqa: E402


def band_energy(x, fs, lo, hi):
    spec = np.fft.rfft(x)
    f = np.fft.rfftfreq(len(x), 1.0 / fs)
    m = (f >= lo) & (f < hi)
    return float(np.sum(np.abs(spec[m]) ** 2))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("wav")
    ap.add_argument("-o", "--output", default="ild.png")
    ap.add_argument("--events", nargs="*", default=[])
    a = ap.parse_args()
    x, fs = read_wav(a.wav)
    if x.shape[0] != 2:
        raise SystemExit(f"{a.wav}: need 2 channels, got {x.shape[0]}")
    win = fs // 4
    t, ild = [], []
    for start in range(0, x.shape[1] - win, win):
        el = band_energy(x[0, start:start + win], fs, 2000, 8000)
        er = band_energy(x[1, start:start + win], fs, 2000, 8000)
        if el > 0 and er > 0 and max(el, er) > 1e-6:
            t.append((start + win / 2) / fs)
            ild.append(10 * np.log10(el / er))
    fig, ax = plt.subplots(figsize=(10, 3.2), constrained_layout=True)
    ax.plot(t, ild, ".-")
    ax.axhline(0, color="gray", lw=0.8)
    top = ax.get_ylim()[1]
    for i, e in enumerate(a.events):
        tt, label = e.split(":", 1)
        ax.axvline(float(tt), color="tab:red", ls="--", lw=0.8)
        # Staggered, right-aligned on the line, so neighbouring labels do not overlap.
        ax.text(float(tt) - 0.1, top * (0.85 - 0.2 * i), label, color="tab:red", fontsize=8,
                ha="right")
    ax.set(xlabel="time (s)", ylabel="ILD 2-8 kHz (dB, + = left)", title=a.wav)
    fig.savefig(a.output, dpi=80)
    for lo, hi in [(0, 5), (5, 10), (10, 15), (15, 17), (17, 20)]:
        sel = [v for tt, v in zip(t, ild) if lo <= tt < hi]
        if sel:
            print(f"{lo:4.0f}-{hi:2.0f} s: ILD median {np.median(sel):+5.1f} dB")
    print(f"wrote {a.output}")


if __name__ == "__main__":
    main()
