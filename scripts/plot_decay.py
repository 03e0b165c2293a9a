#!/usr/bin/python3
"""Per-band energy decay curves (Schroeder EDC) of an energy response, of an exact IR of it, and of a synthesised IR.

Usage: scripts/plot_decay.py ER.csv IR.wav [--source N] [--build DIR] [-o decay.png]

ER.csv comes from `dpc-demo ... --er-out ER.csv`, IR.wav from `--ir-out IR.wav` of the same run
(mono output: channel N+1 is source N). Every curve is dpc-analyze's own band energy
(`--band-energy`), so the picture shows what dpc-analyze's T30/EDT/C80 are computed from:
  - energy response: the response's bins per octave band, the direct sound in its bin;
  - exact IR: what the ISO 3382-1 octave filters read from an IR carrying the response exactly
    (`--as-measured`: the filters' skirts, delay and ringing, no synthesis noise);
  - synthesised IR: the IR through those filters, 1 ms bins from its onset.
The synthesis is right where its curve follows the exact IR's; where the exact IR leaves the
energy response (the 4 and 8 kHz tails of a fast decay under a slower band) the octave filters
are what differ, not the synthesis. All curves start at the IR's onset. Bands whose upper edge
reaches Nyquist are left empty.
"""
import argparse
import csv
import io
import os
import subprocess

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
LABELS = ["63", "125", "250", "500", "1k", "2k", "4k", "8k"]


def band_table(analyze, path, *flags):
    """dpc-analyze --band-energy rows of every channel (IR) or source (energy response)."""
    try:
        run = subprocess.run([analyze, path, "--band-energy", *flags], capture_output=True,
                             text=True)
    except OSError as e:
        raise SystemExit(f"plot_decay: --build: cannot run {analyze}: {e.strerror}")
    if run.returncode != 0:
        raise SystemExit(f"plot_decay: {run.stderr.strip()}")
    rows = [r for r in csv.reader(io.StringIO(run.stdout)) if r and not r[0].startswith("#")]
    return rows[1:]


def band_energy(rows, path, index):
    """(bin start times s, energy [bins x 8] with NaN for empty bands) of one channel/source."""
    rows = [r for r in rows if int(r[0]) == index]
    if not rows:
        raise SystemExit(f"plot_decay: {path}: no rows for index {index}")
    t = np.array([float(r[1]) for r in rows])
    e = np.array([[float(v) if v else np.nan for v in r[2:]] for r in rows])
    return t, e


def edc_db(e):
    tail = np.cumsum(e[::-1])[::-1]
    return 10 * np.log10(np.maximum(tail / tail[0], 1e-12))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("er")
    ap.add_argument("ir")
    ap.add_argument("--source", type=int, default=0)
    ap.add_argument("--build", default=os.path.join(ROOT, "build"),
                    help="build directory holding apps/dpc-analyze")
    ap.add_argument("-o", "--output", default="decay.png")
    a = ap.parse_args()
    analyze = os.path.join(a.build, "apps", "dpc-analyze")
    er_rows, ir_rows = band_table(analyze, a.er), band_table(analyze, a.ir)
    sources, channels = len({r[0] for r in er_rows}), len({r[0] for r in ir_rows})
    if channels != sources:
        raise SystemExit(f"plot_decay: {a.ir}: {channels} channels for the {sources} source(s) of "
                         f"{a.er}: needs a mono IR (dpc-demo --output mono), one channel per "
                         f"source")
    t_er, er = band_energy(er_rows, a.er, a.source)
    t_ex, exact = band_energy(band_table(analyze, a.er, "--as-measured"), a.er, a.source)
    t_ir, ir = band_energy(ir_rows, a.ir, a.source + 1)
    onset = t_ir[0]
    fig, axes = plt.subplots(2, 4, figsize=(14, 6), sharex=True, sharey=True,
                             constrained_layout=True)
    for b, ax in enumerate(axes.flat):
        if not np.isnan(ir[0, b]):
            ax.plot(t_ir - onset, edc_db(ir[:, b]), label="synthesised IR", lw=1.5)
        for t, e, style, label in ((t_ex, exact, ":", "exact IR"),
                                   (t_er, er, "--", "energy response")):
            k0 = int(np.searchsorted(t, onset, side="right")) - 1
            ax.plot(t[k0:] - t[k0], edc_db(e[k0:, b]), style, label=label, lw=1.5)
        ax.set(title=f"{LABELS[b]} Hz", ylim=(-60, 2), xlim=(0, t_er[-1] - onset))
        ax.grid(alpha=0.3)
        if b % 4 == 0:
            ax.set_ylabel("EDC (dB)")
        if b >= 4:
            ax.set_xlabel("time after onset (s)")
    axes.flat[0].legend(fontsize=8)
    fig.suptitle(f"Schroeder decay per octave band: {os.path.basename(a.er)} and an exact IR "
                 f"of it vs {os.path.basename(a.ir)}")
    fig.savefig(a.output, dpi=90)
    print(f"wrote {a.output}")


if __name__ == "__main__":
    main()
