#!/usr/bin/python3
"""A door swung open a few degrees: direct sound re the free field at 63, 125 and 250 Hz.

A 4 cm box leaf hinged at its corner in a 0.2 m wall's doorway, turned 2-15 degrees toward the
source, as a moving object and in the static mesh, against the slit model of its openings
(the latch rim to the jamb's corner, the hinge gap, the slot under the lintel) that
tests/engine/slit_model.h computes on its own. Every number comes from
build/tests/door_swing_test (tests/engine/door_swing_test.cpp).

Usage: scripts/plot_door_swing.py [--build build] [-o docs/images/door-swing.png]
"""
import argparse
import os
import re
import subprocess
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

BANDS = [63, 125, 250]
ROW = re.compile(r"leaf ajar\s+([\d.]+) deg: object / in the mesh / model \(dB\)(.*)")


def read(build):
    test = os.path.join(build, "tests", "door_swing_test")
    if not os.path.exists(test):
        sys.exit(f"plot_door_swing.py: --build: {test}: no such file (build the tests first)")
    out = subprocess.run([test, "-s", "Door swing: a box leaf ajar*"], capture_output=True,
                         text=True).stdout
    rows = []
    for line in out.splitlines():
        m = ROW.match(line)
        if m:
            triples = re.findall(r"(-?\d+\.\d+)/\s*(-?\d+\.\d+)/\s*(-?\d+\.\d+)", m.group(2))
            rows.append((float(m.group(1)), [tuple(map(float, t)) for t in triples]))
    if not rows:
        sys.exit(f"plot_door_swing.py: {test}: printed no 'leaf ajar' rows")
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--build", default="build")
    parser.add_argument("-o", "--output", default="docs/images/door-swing.png")
    args = parser.parse_args()
    rows = read(args.build)
    degrees = [r[0] for r in rows]
    fig, axes = plt.subplots(1, len(BANDS), figsize=(12, 3.8), sharey=True)
    for b, (ax, band) in enumerate(zip(axes, BANDS)):
        for k, (label, style) in enumerate([("engine, moving object", "o-"),
                                            ("engine, in the mesh", "x--"),
                                            ("slit model", "k-")]):
            ax.plot(degrees, [r[1][b][k] for r in rows], style, label=label, ms=4)
        ax.set_title(f"{band} Hz")
        ax.set_xlabel("leaf ajar (degrees)")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("direct sound re free field (dB)")
    axes[0].legend(fontsize=8)
    fig.suptitle("A 4 cm box leaf ajar in a 0.2 m wall: the engine against the slit model of "
                 "its openings")
    fig.tight_layout()
    fig.savefig(args.output, dpi=110)
    print(f"plot_door_swing.py: wrote {args.output}")


if __name__ == "__main__":
    main()
