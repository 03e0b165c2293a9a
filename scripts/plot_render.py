#!/usr/bin/python3
"""Plots a rendered WAV (and optionally its IR): level over time and spectrogram.

Usage: scripts/plot_render.py OUT.wav [IR.wav] [-o plot.png]
"""
import argparse
import wave

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def read_wav(path):
    import struct
    with open(path, "rb") as f:
        data = f.read()
    # Minimal RIFF parser for float32 / PCM16 WAV (what dpc writes and ships).
    pos, fmt, samples = 12, None, None
    while pos + 8 <= len(data):
        cid, size = data[pos:pos + 4], struct.unpack("<I", data[pos + 4:pos + 8])[0]
        body = data[pos + 8:pos + 8 + size]
        if cid == b"fmt ":
            tag, ch, rate = struct.unpack("<HHI", body[:8])
            bits = struct.unpack("<H", body[14:16])[0]
            if tag == 0xFFFE:
                tag = struct.unpack("<H", body[24:26])[0]
            fmt = (tag, ch, rate, bits)
        elif cid == b"data":
            samples = body
        pos += 8 + size + (size & 1)
    tag, ch, rate, bits = fmt
    if tag == 3:
        x = np.frombuffer(samples, dtype="<f4")
    elif bits == 16:
        x = np.frombuffer(samples, dtype="<i2") / 32768.0
    else:
        raise SystemExit(f"{path}: unsupported WAV format {fmt}")
    return x.reshape(-1, ch).T, rate


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("wav")
    ap.add_argument("ir", nargs="?")
    ap.add_argument("-o", "--output", default="render.png")
    a = ap.parse_args()
    x, fs = read_wav(a.wav)
    rows = 3 if a.ir else 2
    fig, ax = plt.subplots(rows, 1, figsize=(11, 3 * rows), constrained_layout=True)
    mono = x.mean(axis=0)
    hop = fs // 50
    n = len(mono) // hop
    level = 10 * np.log10(np.maximum((mono[: n * hop].reshape(n, hop) ** 2).mean(axis=1), 1e-12))
    ax[0].plot(np.arange(n) * hop / fs, level)
    ax[0].set(xlabel="time (s)", ylabel="level (dBFS, 20 ms RMS)", title=a.wav, ylim=(-80, 0))
    ax[1].specgram(mono, NFFT=2048, Fs=fs, noverlap=1536, cmap="magma", vmin=-140)
    ax[1].set(xlabel="time (s)", ylabel="frequency (Hz)", ylim=(0, 12000))
    if a.ir:
        h, hfs = read_wav(a.ir)
        for c, ch in enumerate(h):
            e = np.cumsum((ch ** 2)[::-1])[::-1]
            ax[2].plot(np.arange(len(ch)) / hfs, 10 * np.log10(np.maximum(e / e[0], 1e-12)),
                       label=f"channel {c + 1}")
        ax[2].set(xlabel="time (s)", ylabel="Schroeder decay (dB)", ylim=(-80, 2), title=a.ir)
        ax[2].legend()
    fig.savefig(a.output, dpi=80)
    print(f"wrote {a.output}")


if __name__ == "__main__":
    main()
