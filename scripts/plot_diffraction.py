#!/usr/bin/python3
"""Level behind a thin screen vs listener position and octave band, with Kurze & Anderson.

Usage: scripts/plot_diffraction.py build/diffraction_screen.csv [-o diffraction-screen.png]
The CSV is written by build/tests/diffraction_test "[diffraction]" (tests/engine/diffraction_test.cpp).
"""
import argparse
import csv
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("csv")
    ap.add_argument("-o", "--output", default="diffraction-screen.png")
    a = ap.parse_args()
    rows = defaultdict(list)
    with open(a.csv) as fh:
        for r in csv.DictReader(fh):
            rows[float(r["band_hz"])].append(r)
    fig, ax = plt.subplots(figsize=(9, 5), constrained_layout=True)
    for i, (band, rs) in enumerate(sorted(rows.items())):
        y = [float(r["y"]) for r in rs]
        colour = f"C{i}"
        ax.plot(y, [float(r["level_db"]) for r in rs], color=colour,
                label=f"{band:.0f} Hz, UTD (dpc)")
        ref = [(float(r["y"]), float(r["kurze_anderson_db"])) for r in rs
               if r["kurze_anderson_db"] != "nan"]
        ax.plot([p[0] for p in ref], [p[1] for p in ref], "--", color=colour, lw=1)
    ax.axvline(1.0, color="k", lw=0.8)
    ax.text(1.02, -28, "shadow boundary", rotation=90)
    ax.set(xlabel="listener height y (m); screen top at 0, listener 5 m behind, source 5 m before, 1 m down",
           ylabel="level re free field (dB)", ylim=(-30, 3), xlim=(2, -4),
           title="Thin screen: dpc UTD (solid) vs Kurze-Anderson (dashed, shadow zone)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, ncol=2)
    fig.savefig(a.output, dpi=90)
    print(f"wrote {a.output}")


if __name__ == "__main__":
    main()
