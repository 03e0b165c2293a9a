#!/usr/bin/python3
"""Writes the seed corpus of fuzz/c_api_fuzzer.cpp into fuzz/corpus/c_api: byte encodings, in
the fuzzer's decoding order, of the 6 x 3 x 4 m box of tests/api/box_data.h (valid, stereo and
mono), the same box with diffraction and a second source, and the box with a listener at NaN,
a vertex at 1e20 and a listener sphere of infinite radius (refusals). The valid seeds are
named valid-*: ctest fuzz_replay:c_api fails when the fuzzer refuses one (fuzz/fuzz_report.h).

Usage: fuzz/make_c_api_seeds.py
"""
import os
import struct

BOX_VERTICES = [(0, 0, 0), (6, 0, 0), (6, 3, 0), (0, 3, 0), (0, 0, 4), (6, 0, 4), (6, 3, 4),
                (0, 3, 4)]
BOX_TRIANGLES = [(0, 1, 2), (0, 2, 3), (4, 6, 5), (4, 7, 6), (0, 4, 5), (0, 5, 1), (3, 2, 6),
                 (3, 6, 7), (0, 3, 7), (0, 7, 4), (1, 5, 6), (1, 6, 2)]


def small(x):
    """A small float: selector 0, then x * 4 as a signed byte."""
    q = int(round(x * 4))
    assert -128 <= q <= 127 and q / 4 == x, x
    return bytes([0, q & 0xFF])


def raw(x):
    """A raw float: selector 1, then its bits."""
    return bytes([1]) + struct.pack("<f", x)


def box(sources=1, diffraction=0, listener_x=None, vertex0=None, radius=None, output=2):
    b = bytearray([len(BOX_VERTICES), len(BOX_TRIANGLES)])
    for i, v in enumerate(BOX_VERTICES):
        for k, c in enumerate(v):
            b += raw(vertex0) if (i, k) == (0, 0) and vertex0 is not None else small(c)
    for t in BOX_TRIANGLES:
        b += bytes(t)
    b += bytes([1])                      # material_count 1
    b += bytes([0] * len(BOX_TRIANGLES))  # every triangle material 0
    for _ in range(4):                   # scattering, then 8 absorption coefficients
        b += small(0.25) + small(0.25) * 8
    b += bytes([sources])
    for s in range(4):
        b += small(2 + s * 0.5) + small(1.5) + small(2) + small(0)
    b += (raw(listener_x) if listener_x is not None else small(4)) + small(1.5) + small(2)
    # radius, yaw, pitch
    b += (raw(radius) if radius is not None else small(0.5)) + small(0) + small(0)
    b += small(0)                          # roll
    b += bytes([0])                        # no additional listener
    for _ in range(3):
        b += small(4) + small(1.5) + small(2) + small(0.5) + small(0) + small(0) + small(0)
    b += bytes([0])                        # additional_listeners pointer set
    b += bytes([0, 32, 0, 8])              # rays 32, max_order 8
    b += small(0.5) + small(1) + small(15) + small(0.25)  # patch, tau, frame rate, ir length
    b += struct.pack("<I", 7)              # seed
    b += small(0) + small(20) + small(30)  # speed of sound (0: from temperature), T, humidity
    b += bytes([1, diffraction, 0, 0, output])  # air absorption, diffraction, 48 kHz, 256, output
    b += bytes([1])                        # ambisonic order 1 (read for every output)
    b += small(2) + small(1.5) + small(2)  # set_source_position
    b += small(4) + small(1.5) + small(2) + small(0) + small(0)  # set_listener_pose
    return bytes(b)


def main():
    out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "corpus", "c_api")
    os.makedirs(out, exist_ok=True)
    seeds = {"valid-box": box(), "valid-box-mono": box(output=1),
             "valid-box-diffraction-2-sources": box(sources=2, diffraction=1),
             "box-listener-nan": box(listener_x=float("nan")), "box-vertex-1e20": box(vertex0=1e20),
             "box-radius-inf": box(radius=float("inf"))}
    for name, data in seeds.items():
        with open(os.path.join(out, name), "wb") as f:
            f.write(data)


if __name__ == "__main__":
    main()
