#!/usr/bin/python3
"""Polar plots of source directivity: dpc's rays and direct sound vs the first-order pattern.

Usage: scripts/plot_directivity.py build/directivity_polar.csv [-o directivity-polar.png]
The CSV is written by build/tests/source_directivity_test "Emitted rays*"
(tests/engine/source_directivity_test.cpp): per pattern and angle from the forward axis, the
level of the order-0 rays through a 0.5 m sphere 4 m away, of the analytic direct sound, and of
the pattern g / <g>, all in dB re an omni source of the same power. The patterns are
symmetric about the forward axis, so 0..180 degrees is mirrored to a full turn.
"""
import argparse
import csv
import math
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

FLOOR_DB = -30.0


def clip(db):
    return max(FLOOR_DB, db) if math.isfinite(db) else FLOOR_DB


def mirrored(rows, key):
    """Angles (radians) and levels over a full turn from the 0..180 degree rows."""
    ang = [math.radians(float(r["angle_deg"])) for r in rows]
    lev = [clip(float(r[key])) for r in rows]
    return ang + [2 * math.pi - a for a in reversed(ang)], lev + lev[::-1]


def pattern_db(a, theta):
    """10 lg of ((1 - a) + a cos theta)^2 / ((1 - a)^2 + a^2 / 3): the same formula as
    scene/directivity.h, drawn densely."""
    g = ((1 - a) + a * math.cos(theta)) ** 2
    return clip(10 * math.log10(g / ((1 - a) ** 2 + a * a / 3))) if g > 0 else FLOOR_DB


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("csv")
    ap.add_argument("-o", "--output", default="directivity-polar.png")
    a = ap.parse_args()
    by_pattern = defaultdict(list)
    with open(a.csv) as fh:
        for r in csv.DictReader(fh):
            by_pattern[r["pattern"]].append(r)
    fig, axes = plt.subplots(1, len(by_pattern), subplot_kw={"projection": "polar"},
                             figsize=(4 * len(by_pattern), 4.4), constrained_layout=True)
    for ax, (name, rows) in zip(axes, by_pattern.items()):
        dense = [2 * math.pi * k / 720 for k in range(721)]
        a_value = float(rows[0]["a"])
        ax.plot(dense, [pattern_db(a_value, t) for t in dense], "k-", lw=1, label="pattern g/<g>")
        ax.plot(*mirrored(rows, "direct_db"), "C0o", ms=3, label="direct sound (dpc)")
        ax.plot(*mirrored(rows, "rays_db"), "C3x", ms=5, label="rays, 2e6 (dpc)")
        ax.set_ylim(FLOOR_DB, 8)
        ax.set_yticks([-30, -20, -10, 0])
        ax.set_title(f"{name} (a = {rows[0]['a']})", fontsize=10)
    axes[0].legend(loc="lower left", fontsize=7, bbox_to_anchor=(-0.15, -0.15))
    fig.suptitle("Source directivity at 1 kHz, dB re omni of the same power; forward = 0 deg")
    fig.savefig(a.output, dpi=80)
    print(f"wrote {a.output}")


if __name__ == "__main__":
    main()
