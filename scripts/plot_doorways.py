#!/usr/bin/python3
"""Doors and doorways on the line of sight: direct sound re the free field per octave band.

Left: the open doorway in a thin wall and through a 0.3 m wall (faces written once or twice)
against the Kirchhoff aperture integral. Middle: closed doors, one leaf with gaps round it and
two leaves meeting in the middle, against the slit model, with the open doorway for reference.
Third: real doors, a 4 cm box leaf set in the middle of a 0.2 m wall, in the static mesh and
as a moving object, against the slit model with the leaf's thickness as the slits' depth.
Right: the same leaf closed against a door stop (15 mm lip, 0.2 m wall) on the listener's side
or the source's, against the slit model with the L-shaped gap's centre line as the depth.
Every number comes from build/tests/doorway_test, door_gap_test and door_frame_test
(tests/engine/), which compute the Kirchhoff integral and the slit model on their own.

Usage: scripts/plot_doorways.py [--build build] [-o docs/images/doorways.png]
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


def numbers(text):
    return [float(v) for v in re.findall(r"-?\d+\.\d+", text)]


def read(build):
    out = ""
    for name in ("doorway_test", "door_gap_test", "door_frame_test"):
        test = os.path.join(build, "tests", name)
        if not os.path.exists(test):
            sys.exit(f"plot_doorways.py: --build: {test}: no such file (build the tests first)")
        out += subprocess.run([test, "-s", "Do*"], capture_output=True, text=True).stdout
    open_rows, table, double, box, stop = {}, {}, [], {}, {}
    for line in out.splitlines():
        m = re.match(r"wall 0\.2 m, stop (behind|before), lip 15 mm, gap\s+(\d+) mm: "
                     r"dpc, dpc - model \(dB\)(.*)", line)
        if m:
            pairs = re.findall(r"(-?\d+\.\d+)/([+-]\d+\.\d+)", m.group(3))
            stop[(m.group(1), m.group(2))] = ([float(a) for a, _ in pairs],
                                              [float(a) - float(d) for a, d in pairs])
        m = re.match(r"(wall 0\.2 m, leaf 40 mm at x 6\.10|object box leaf at x 6\.10), gap\s+(\d+) mm: "
                     r"dpc, dpc - model \(dB\)(.*)", line)
        if m:
            pairs = re.findall(r"(-?\d+\.\d+)/([+-]\d+\.\d+)", m.group(3))
            kind = "object" if m.group(1).startswith("object") else "static"
            box[(kind, m.group(2))] = ([float(a) for a, _ in pairs],
                                       [float(a) - float(d) for a, d in pairs])
        m = re.match(r"doorway (.+?)\s+\(dB re free field\)(.*)", line)
        if m:
            open_rows[m.group(1).strip()] = numbers(m.group(2))
        m = re.match(r"\| (\d+ mm) \| (closed, leaf in the mesh|slit model \(this test\)) \|(.*)",
                     line)
        if m and m.group(3).split("|")[0].strip() != "-":  # "-": nothing passes (0 mm)
            table[(m.group(1), m.group(2))] = numbers(m.group(3))
        m = re.match(r"double door,\s+(\d+) mm round,\s+(\d+) mm between: closed / model \(dB\)(.*)",
                     line)
        if m:
            pairs = re.findall(r"(-?\d+\.\d+)/\s*(-?\d+\.\d+)", m.group(3))
            double.append((m.group(1), m.group(2), [float(a) for a, _ in pairs],
                           [float(b) for _, b in pairs]))
    if not open_rows or not table or not double or not box or not stop:
        sys.exit("plot_doorways.py: door_gap_test or door_frame_test printed none of its tables "
                 "(did it fail?)")
    return open_rows, table, double, box, stop


def against_model(ax, open_level, rows, gaps, variants):
    """The open doorway, then per gap (one colour) each variant's dpc levels (its marker and
    dash) and, for the first variant, the slit model dashed; rows[(variant, gap)] = (dpc,
    model)."""
    ax.plot(BANDS, open_level, "k-", lw=2, label="open doorway, 0.3 m wall (dpc)")
    for i, gap in enumerate(gaps):
        for n, (kind, marker, dash, label) in enumerate(variants):
            if (kind, gap) not in rows:
                continue
            dpc, model = rows[(kind, gap)]
            ax.plot(BANDS, dpc, dash, color=f"C{i}", marker=marker, label=label.format(gap))
            if n == 0:
                ax.plot(BANDS, model, "--", color=f"C{i}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--build", default="build")
    ap.add_argument("-o", "--output", default="docs/images/doorways.png")
    a = ap.parse_args()
    open_rows, table, double, box, stop = read(a.build)
    fig, (left, right, real, stopped) = plt.subplots(1, 4, figsize=(22, 5), sharey=True,
                                                     constrained_layout=True)
    styles = {"Kirchhoff": ("k", "--"), "thin": ("C0", "-"), "0.3 m": ("C1", "-"),
              "0.3 m twice": ("C2", ":")}
    for name, level in open_rows.items():
        colour, dash = styles.get(name, ("C3", "-"))
        label = {"Kirchhoff": "Kirchhoff aperture integral", "thin": "thin wall (dpc)",
                 "0.3 m": "0.3 m wall (dpc)", "0.3 m twice": "0.3 m wall, faces twice (dpc)"}
        left.plot(BANDS, level, dash, color=colour, marker="o", label=label.get(name, name))
    left.set(title="Open doorway, 1 x 2.1 m, source and listener 3 m either side",
             ylabel="direct sound re free field (dB)")
    right.plot(BANDS, open_rows["thin"], "k-", lw=2, label="open doorway (dpc)")
    for i, gap in enumerate(["5 mm", "10 mm", "20 mm"]):
        right.plot(BANDS, table[(gap, "closed, leaf in the mesh")], "-", color=f"C{i}",
                   marker="o", label=f"one leaf, {gap} round (dpc)")
        right.plot(BANDS, table[(gap, "slit model (this test)")], "--", color=f"C{i}")
    for j, (round_mm, between, dpc, model) in enumerate(double):
        if between != "5":
            continue
        colour = f"C{3 + j}"
        right.plot(BANDS, dpc, "-", color=colour, marker="s",
                   label=f"two leaves 5 mm apart, {round_mm} mm round (dpc)")
        right.plot(BANDS, model, "--", color=colour)
    right.set(title="Closed: dpc (solid) against the slit model (dashed)")
    against_model(real, open_rows["0.3 m"], box, ["5", "10", "20"],
                  (("static", "o", "-", "{} mm round, leaf in the mesh (dpc)"),
                   ("object", "x", ":", "{} mm round, leaf a moving object (dpc)")))
    real.set(title="4 cm box leaf, 0.2 m wall; slit model with depth dashed")
    against_model(stopped, open_rows["0.3 m"], stop, ["3", "5", "10"],
                  (("behind", "o", "-", "{} mm gaps, stop on the listener's side (dpc)"),
                   ("before", "x", ":", "{} mm gaps, stop on the source's side (dpc)")))
    stopped.set(title="That leaf against a 15 mm door stop; model dashed")
    for ax in (left, right, real, stopped):
        ax.set_ylim(-50, 4)  # room below the curves for the legend
        ax.set_xscale("log")
        ax.set_xticks(BANDS, [str(b) for b in BANDS])
        ax.set_xlabel("octave band (Hz)")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8, loc="lower left")
    fig.savefig(a.output, dpi=110)
    print(f"plot_doorways.py: wrote {a.output}")


if __name__ == "__main__":
    main()
