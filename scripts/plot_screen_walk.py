#!/usr/bin/python3
"""A listener walking behind a slatted screen: direct sound re the free field, per octave.

Every number the engine gives comes from the test that checks it (build/tests/edge_chain_test):
- left: nine slats 30 mm across and 50 mm deep, 3 mm apart (0.294 m wide), floor to ceiling
  midway between a source and a listener 6 m apart, the listener walking from behind the
  screen's middle to past its end in 1 cm steps; against Kirchhoff's field behind a solid strip
  of the screen's outline (computed here with SciPy's Fresnel integrals, not the test's own
  Simpson sum; floor and ceiling are images of the strip's infinite height);
- right: 61 such slats (2.01 m wide), 2 m tall on the floor of a 3 m room, where the way over
  the top crosses the slats' tops (no closed-form oracle: the strip has a top).

Usage: scripts/plot_screen_walk.py [--build build] [-o docs/images/screen-walk.png]
"""
import argparse
import os
import re
import subprocess
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from scipy.special import fresnel  # noqa: E402

BANDS = [63, 125, 250, 500, 1000, 2000, 4000, 8000]
SHOWN = [63, 250, 1000, 4000]
SPEED = 343.0  # m/s, as the test
WIDTH = 9 * 0.03 + 8 * 0.003  # m, the nine-slat screen
HALF_DISTANCE = 3.0  # m, source and listener to the screen
ROW = re.compile(r"(slatted|wide) screen, listener\s+([\d.]+) m off \(dB\)(.*)")


def read(build):
    """Per screen ('slatted', 'wide'), rows of (offset m, [dB per band])."""
    test = os.path.join(build, "tests", "edge_chain_test")
    if not os.path.exists(test):
        sys.exit(f"plot_screen_walk.py: --build: {test}: no such file (build the tests first)")
    out = subprocess.run([test, "-s", "*slatted screen*"], capture_output=True, text=True).stdout
    rows = {"slatted": [], "wide": []}
    for m in map(ROW.match, out.splitlines()):
        if m:
            rows[m.group(1)].append((float(m.group(2)), [float(v) for v in m.group(3).split()]))
    if not rows["slatted"] or not rows["wide"]:
        sys.exit(f"plot_screen_walk.py: {test}: printed no screen rows")
    return rows


def kirchhoff_db(offset, hz):
    """Kirchhoff's field behind the solid strip, the listener `offset` m off the axis (dB)."""
    lam = SPEED / hz
    crossing = offset * 0.5  # where the line of sight crosses the screen's plane
    scale = np.sqrt(2 * (2 * HALF_DISTANCE) / (lam * HALF_DISTANCE * HALF_DISTANCE))
    s0, c0 = fresnel((-0.5 * WIDTH - crossing) * scale)
    s1, c1 = fresnel((0.5 * WIDTH - crossing) * scale)
    blocked = (c1 - c0) + 1j * (s1 - s0)
    return 20 * np.log10(abs(1 - (0.5 - 0.5j) * blocked))


def plot(rows, output):
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2), sharey=True)
    colours = dict(zip(SHOWN, ["C0", "C1", "C2", "C3"]))
    for ax, name, title in ((axes[0], "slatted", "0.29 m screen, floor to ceiling"),
                            (axes[1], "wide", "2 m screen, 2 m tall (a way over the top)")):
        x = np.array([r[0] for r in rows[name]]) * 100
        for hz in SHOWN:
            level = [r[1][BANDS.index(hz)] for r in rows[name]]
            ax.plot(x, level, "o-", ms=3, color=colours[hz], label=f"dpc {hz} Hz")
            if name == "slatted":
                oracle = [kirchhoff_db(r[0], hz) for r in rows[name]]
                ax.plot(x, oracle, "--", color=colours[hz], label=f"solid strip {hz} Hz")
        if name == "slatted":
            ax.axvline(WIDTH * 100, color="grey", lw=0.8)
            ax.text(WIDTH * 100 + 0.3, -9.5, "line of sight\npasses the end", fontsize=8)
        ax.axhline(1.37, color="grey", lw=0.8, ls=":")
        ax.set_title(title, fontsize=10)
        ax.set_xlabel("listener off the axis (cm), 1 cm steps")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("direct sound re free field (dB)")
    axes[0].legend(fontsize=7, ncol=2, loc="lower left")
    fig.suptitle("Walking behind a slatted screen (slats 30 mm, slots 3 mm): the ways round its "
                 "ends and over its top", fontsize=10)
    fig.tight_layout()
    fig.savefig(output, dpi=110)
    print(f"plot_screen_walk.py: wrote {output}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--build", default="build", help="build folder holding tests/edge_chain_test")
    ap.add_argument("-o", "--output", default="docs/images/screen-walk.png", help="PNG to write")
    args = ap.parse_args()
    folder = os.path.dirname(os.path.abspath(args.output))
    if not os.path.isdir(folder):
        sys.exit(f"plot_screen_walk.py: --output: {folder}: no such folder")
    plot(read(args.build), args.output)


if __name__ == "__main__":
    main()
