#!/usr/bin/python3
"""Behind a free-standing thin panel: the engine's direct sound per octave against the
first-order Biot-Tolstoy-Medwin field of the panel's four edges.

Every number comes from the test that checks it (build/tests/finite_edge_test, "behind a
free-standing panel"): panels 2 x 2, 1 x 4, 4 x 2 and 1 x 1 m midway between a source and
listeners 6 m apart, 0 to 0.75 m off the axis. The oracle is the test's own line integral of
each edge's secondary sources (testing/btm_edges.h), which shares nothing with the engine's
UTD sum and its finite-edge factor (engine/finite_edge.h). Where the edges' field passes the
free field (panels under a wavelength), a blocked line of sight is held at it: the grey line.

Usage: scripts/plot_finite_edges.py [--build build] [-o docs/images/finite-edges.png]
"""
import argparse
import os
import re
import subprocess
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

BANDS = [63, 125, 250, 500, 1000, 2000, 4000, 8000]
ROW = re.compile(r"panel (\d+) x (\d+) m, ([\d.]+) m off the axis: dpc / BTM \(dB\)(.*)")
PAIR = re.compile(r"(-?[\d.]+)/\s*(-?[\d.]+)")


def read_rows(build):
    """{(width, height): [(offset, engine levels, BTM levels)]} from the test's output."""
    binary = os.path.join(build, "tests", "finite_edge_test")
    if not os.access(binary, os.X_OK):
        sys.exit("plot_finite_edges: --build %s: no tests/finite_edge_test" % build)
    out = subprocess.run([binary, "Finite edges: behind a free-standing panel*"],
                         capture_output=True, text=True).stdout
    panels = {}
    for line in out.splitlines():
        m = ROW.match(line)
        if not m:
            continue
        pairs = PAIR.findall(m.group(4))
        panels.setdefault((m.group(1), m.group(2)), []).append(
            (float(m.group(3)), [float(a) for a, _ in pairs], [float(b) for _, b in pairs]))
    if not panels:
        sys.exit("plot_finite_edges: %s printed no panel rows" % binary)
    return panels


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", default="build")
    ap.add_argument("-o", "--output", default="docs/images/finite-edges.png")
    args = ap.parse_args()
    folder = os.path.dirname(args.output)
    if folder and not os.path.isdir(folder):
        sys.exit("plot_finite_edges: --output %s: no folder %s" % (args.output, folder))
    panels = read_rows(args.build)
    fig, axes = plt.subplots(1, len(panels), figsize=(3.6 * len(panels), 3.8), sharey=True)
    x = range(len(BANDS))
    for ax, ((w, h), rows) in zip(axes, panels.items()):
        for offset, engine, btm in rows:
            line, = ax.plot(x, btm, "-", label="BTM, %.2f m off" % offset)
            ax.plot(x, engine, "o", color=line.get_color(), markersize=4)
        ax.axhline(0.0, color="grey", linewidth=0.8)
        ax.set_xticks(list(x))
        ax.set_xticklabels([("%gk" % (b / 1000)) if b >= 1000 else str(b) for b in BANDS],
                           fontsize=7)
        ax.set_title("panel %s x %s m" % (w, h))
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("direct sound re free field (dB)")
    axes[0].set_xlabel("octave band (Hz)")
    axes[-1].legend(fontsize=7)
    fig.suptitle("Behind a free-standing panel: the engine (dots) against first-order BTM "
                 "of its edges (lines)")
    fig.tight_layout()
    fig.savefig(args.output, dpi=110)
    print("plot_finite_edges: wrote %s" % args.output)


if __name__ == "__main__":
    main()
