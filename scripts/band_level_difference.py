#!/usr/bin/python3
"""Level difference per octave band and channel between two renders of the same scene.

Usage: scripts/band_level_difference.py REFERENCE.wav TEST.wav [--analyze build/apps/dpc-analyze]

Each channel's energy per octave band (63 Hz .. 8 kHz) is the sum of dpc-analyze
--band-energy's 1 ms bins (its ISO 3382-1 octave filters, from the first arrival on); printed
per channel: 10 log10(TEST / REFERENCE), dB. Python's standard library only.
"""
import argparse
import csv
import math
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def band_totals(analyze, wav, channel):
    out = subprocess.run([analyze, wav, "--band-energy", "--channel", str(channel)],
                         check=True, capture_output=True, text=True).stdout
    rows = list(csv.reader(line for line in out.splitlines() if not line.startswith("#")))
    header, data = rows[0], rows[1:]
    return header[2:], [sum(float(r[i]) for r in data) for i in range(2, len(header))]


def channels(wav):
    """The channel count in the WAV file's fmt chunk."""
    with open(wav, "rb") as f:
        data = f.read(4096)
    at = data.find(b"fmt ")
    if data[:4] != b"RIFF" or at < 0:
        sys.exit(f"{wav}: not a RIFF/WAVE file with a fmt chunk in its first 4 KB")
    return int.from_bytes(data[at + 10:at + 12], "little")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("reference")
    ap.add_argument("test")
    ap.add_argument("--analyze", default=os.path.join(ROOT, "build", "apps", "dpc-analyze"))
    a = ap.parse_args()
    n = channels(a.reference)
    if channels(a.test) != n:
        sys.exit(f"{a.test}: {channels(a.test)} channels, {a.reference} has {n}")
    for c in range(1, n + 1):
        bands, ref = band_totals(a.analyze, a.reference, c)
        _, test = band_totals(a.analyze, a.test, c)
        if c == 1:
            print("channel " + " ".join(f"{b:>6}" for b in bands))
        print(f"{c:>7} " + " ".join(f"{10 * math.log10(t / r):+6.1f}" for t, r in zip(test, ref)))


if __name__ == "__main__":
    main()
