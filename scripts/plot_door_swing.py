#!/usr/bin/python3
"""A door swung open a few degrees: direct sound re the free field at 63, 125 and 250 Hz.

Two figures, every number from the tests that check them:
- door-swing.png: a 4 cm box leaf hinged at its corner in a 0.2 m wall's doorway, turned 2-15
  degrees toward the source, as a moving object and in the static mesh, against the slit model
  of its openings (the latch rim to the jamb's corner, the hinge gap, the slot under the
  lintel) that tests/engine/slit_model.h computes on its own (build/tests/door_swing_test).
- door-stop-swing.png: the same leaf hinged on its centre line and closed against a door stop
  behind or before it, turned away from the stop 0.5-8 degrees, against the leaf shut and the
  slit model of its openings without the stop (build/tests/door_stop_swing_test).
- door-swing-away.png: a 4 cm box leaf in a 0.1 m wall standing alone, turned 1-29 degrees
  toward the source, heard 1 m off the axis past the latch jamb, as a moving object and in the
  mesh, against the leaf shut and the slit model of its openings to 15 degrees
  (build/tests/door_swing_test).

Usage: scripts/plot_door_swing.py [--build build] [-o docs/images/door-swing.png]
                                  [--stop-output docs/images/door-stop-swing.png]
                                  [--away-output docs/images/door-swing-away.png]
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
SWING = re.compile(r"leaf ajar\s+([\d.]+) deg: object / in the mesh / model \(dB\)(.*)")
AWAY = re.compile(r"leaf\s+([\d.]+) deg toward S, beside: object / mesh / model(.*)")
AWAY_SHUT = re.compile(r"shut, beside: object / mesh \(dB\)(.*)")
STOP = re.compile(r"stop (behind|before), ajar\s+([\d.]+) deg: "
                  r"object / in the mesh / shut / model / upper \(dB\)(.*)")


def run(build, name, case):
    """The test's printed output, or exit naming the missing binary."""
    test = os.path.join(build, "tests", name)
    if not os.path.exists(test):
        sys.exit(f"plot_door_swing.py: --build: {test}: no such file (build the tests first)")
    return test, subprocess.run([test, "-s", case], capture_output=True, text=True).stdout


def columns(text, n):
    """Per band, the n slash-separated levels of one printed row."""
    number = r"\s*(-?\d+\.\d+)"
    found = re.findall("/".join([number] * n), text)
    return [tuple(map(float, t)) for t in found]


def read_swing(build):
    test, out = run(build, "door_swing_test", "Door swing: a box leaf ajar*")
    rows = [(float(m.group(1)), columns(m.group(2), 3))
            for m in map(SWING.match, out.splitlines()) if m]
    if not rows:
        sys.exit(f"plot_door_swing.py: {test}: printed no 'leaf ajar' rows")
    return rows


def read_stop(build):
    test, out = run(build, "door_stop_swing_test", "Door stop: *")
    rows = {"behind": [], "before": []}
    for m in map(STOP.match, out.splitlines()):
        if m:
            rows[m.group(1)].append((float(m.group(2)), columns(m.group(3), 5)))
    if not rows["behind"] or not rows["before"]:
        sys.exit(f"plot_door_swing.py: {test}: printed no 'stop behind/before' rows")
    return rows


def read_away(build):
    test, out = run(build, "door_swing_test", "*swung 1-29 degrees toward the source*")
    rows = [(float(m.group(1)), columns(m.group(2), 3))
            for m in map(AWAY.match, out.splitlines()) if m]
    shut = [columns(m.group(1), 2) for m in map(AWAY_SHUT.match, out.splitlines()) if m]
    if not rows or not shut:
        sys.exit(f"plot_door_swing.py: {test}: printed no 'toward S' or 'shut, beside' rows")
    return rows, shut[0]


def finish(fig, first, title, output):
    """Labels the first panel (level axis, legend), titles the figure and writes it."""
    first.set_ylabel("direct sound re free field (dB)")
    first.legend(fontsize=8)
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(output, dpi=110)
    print(f"plot_door_swing.py: wrote {output}")


def plot_away(data, output):
    rows, shut = data
    degrees = [r[0] for r in rows]
    fig, axes = plt.subplots(1, len(BANDS), figsize=(12, 3.8), sharey=True)
    for b, (ax, band) in enumerate(zip(axes, BANDS)):
        ax.plot(degrees, [r[1][b][0] for r in rows], "o-", label="engine, moving object", ms=4)
        ax.plot(degrees, [r[1][b][1] for r in rows], "x--", label="engine, in the mesh", ms=4)
        model = [(d, r[1][b][2]) for d, r in zip(degrees, rows) if d <= 15.0]
        ax.plot([m[0] for m in model], [m[1] for m in model], "k-", label="slit model")
        ax.axhline(shut[b][0], color="k", ls=":", label="shut")
        ax.set_title(f"{band} Hz")
        ax.set_xlabel("leaf turned toward the source (degrees)")
        ax.grid(alpha=0.3)
    finish(fig, axes[0], "A 4 cm box leaf swung toward the source, heard 1 m off the axis past "
           "its latch jamb", output)


def plot_swing(rows, output):
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
    finish(fig, axes[0], "A 4 cm box leaf ajar in a 0.2 m wall: the engine against the slit "
           "model of its openings", output)


def plot_stop(rows, output):
    fig, axes = plt.subplots(2, len(BANDS), figsize=(12, 7), sharey=True, sharex=True)
    for s, side in enumerate(["behind", "before"]):
        degrees = [r[0] for r in rows[side]]
        for b, band in enumerate(BANDS):
            ax = axes[s][b]
            for k, (label, style) in enumerate([("engine, moving object", "o-"),
                                                ("engine, in the mesh", "x--"),
                                                ("shut", "k:"),
                                                ("slit model without the stop", "k-")]):
                ax.plot(degrees, [r[1][b][k] for r in rows[side]], style, label=label, ms=4)
            ax.axvspan(0, 3, color="0.9", zorder=0)
            ax.set_title(f"stop {side} the leaf, {band} Hz")
            ax.grid(alpha=0.3)
        axes[s][0].set_ylabel("direct sound re free field (dB)")
    for ax in axes[1]:
        ax.set_xlabel("turned from its stop (degrees)")
    axes[0][0].legend(fontsize=8)
    fig.suptitle("A 4 cm box leaf against a door stop, opened a few degrees (shaded: its latch rim still in the reveal)")
    fig.tight_layout()
    fig.savefig(output, dpi=110)
    print(f"plot_door_swing.py: wrote {output}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--build", default="build")
    parser.add_argument("-o", "--output", default="docs/images/door-swing.png")
    parser.add_argument("--stop-output", default="docs/images/door-stop-swing.png")
    parser.add_argument("--away-output", default="docs/images/door-swing-away.png")
    args = parser.parse_args()
    plot_swing(read_swing(args.build), args.output)
    plot_stop(read_stop(args.build), args.stop_output)
    plot_away(read_away(args.build), args.away_output)


if __name__ == "__main__":
    main()
