#!/usr/bin/python3
"""Sound-field picture of an AmbiX impulse response: energy over azimuth and elevation.

Usage: scripts/plot_soundfield.py IR.wav [-o docs/images/ambisonic-soundfield.png]
IR.wav: dpc-demo --output ambisonics --ambisonic-order 3 --ir-out IR.wav with one source
(16 channels, ACN order, SN3D). A max-rE sampling decoder is steered over a 2-degree grid,
g(u) = sum_n (2n + 1) a_n sum_m Y_nm(u) h_nm(t), and its energy summed over two windows: the
direct sound (its first 2.5 ms) and the early reflections (2.5 to 30 ms after it), each in dB
re its window's maximum. The SN3D harmonics are the closed forms tabulated for AmbiX (Nachbar
et al. 2011), orders 0..3; a_n = P_n(r_E), r_E = 0.861136 (largest root of P_4).
"""
import argparse
import struct

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

RE3 = 0.861136311594053  # largest root of P_4 (Abramowitz & Stegun, Table 25.4)


def read_wav(path):
    """Float32 or int16 PCM WAV (RIFF, format 1, 3 or extensible) -> (rate, [channels x n])."""
    data = open(path, "rb").read()
    pos, fmt, rate, nch, bits, samples = 12, None, 0, 0, 0, None
    while pos + 8 <= len(data):
        cid, size = data[pos:pos + 4], struct.unpack("<I", data[pos + 4:pos + 8])[0]
        body = data[pos + 8:pos + 8 + size]
        if cid == b"fmt ":
            fmt, nch, rate = struct.unpack("<HHI", body[:8])
            bits = struct.unpack("<H", body[14:16])[0]
            if fmt == 0xFFFE:
                fmt = struct.unpack("<H", body[24:26])[0]
        elif cid == b"data":
            samples = body
        pos += 8 + size + (size & 1)
    dtype = np.float32 if fmt == 3 else {16: np.int16, 32: np.int32}[bits]
    x = np.frombuffer(samples, dtype=dtype).astype(np.float64)
    return rate, x.reshape(-1, nch).T


def sn3d_order3(az, el):
    """ACN 0..15 SN3D real spherical harmonics, arrays of azimuth and elevation (radians)."""
    s, c = np.sin(el), np.cos(el)
    r3 = np.sqrt(3.0)
    return np.array([
        np.ones_like(az), np.sin(az) * c, s, np.cos(az) * c,
        r3 / 2 * c * c * np.sin(2 * az), r3 / 2 * np.sin(2 * el) * np.sin(az),
        (3 * s * s - 1) / 2, r3 / 2 * np.sin(2 * el) * np.cos(az),
        r3 / 2 * c * c * np.cos(2 * az),
        np.sqrt(5 / 8) * c ** 3 * np.sin(3 * az), np.sqrt(15) / 2 * s * c * c * np.sin(2 * az),
        np.sqrt(3 / 8) * c * (5 * s * s - 1) * np.sin(az), s * (5 * s * s - 3) / 2,
        np.sqrt(3 / 8) * c * (5 * s * s - 1) * np.cos(az),
        np.sqrt(15) / 2 * s * c * c * np.cos(2 * az), np.sqrt(5 / 8) * c ** 3 * np.cos(3 * az)])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("ir")
    ap.add_argument("-o", "--out", default="docs/images/ambisonic-soundfield.png")
    args = ap.parse_args()
    rate, h = read_wav(args.ir)
    if h.shape[0] != 16:
        raise SystemExit(f"{args.ir}: {h.shape[0]} channels, expected 16 (order 3, one source)")
    weights = np.array([(2 * n + 1) * np.polynomial.legendre.Legendre.basis(n)(RE3)
                        for n in range(4) for _ in range(2 * n + 1)])
    az, el = np.meshgrid(np.radians(np.arange(-180, 181, 2)), np.radians(np.arange(-90, 91, 2)))
    y = sn3d_order3(az.ravel(), el.ravel()) * weights[:, None]  # 16 x directions
    onset = int(np.argmax(np.abs(h[0]) > 0.1 * np.abs(h[0]).max()))
    windows = [("direct sound", onset - int(0.001 * rate), onset + int(0.0025 * rate)),
               ("early reflections, 2.5-30 ms", onset + int(0.0025 * rate),
                onset + int(0.03 * rate))]
    fig, axes = plt.subplots(1, 2, figsize=(12, 3.8), constrained_layout=True)
    for ax, (title, a, b) in zip(axes, windows):
        beams = y.T @ h[:, max(0, a):b]
        e = (beams ** 2).sum(axis=1).reshape(az.shape)
        db = 10 * np.log10(np.maximum(e / e.max(), 1e-3))
        im = ax.pcolormesh(np.degrees(az), np.degrees(el), db, vmin=-30, vmax=0,
                           cmap="magma", shading="auto")
        ax.set_title(title)
        ax.set_xlabel("azimuth (degrees, + = left)")
        ax.set_ylabel("elevation (degrees)")
        ax.invert_xaxis()
    fig.colorbar(im, ax=axes, label="dB re window maximum")
    fig.savefig(args.out, dpi=110)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
