#!/usr/bin/python3
"""Plots `dpc-bench convolve` JSON: CPU per case and block size for dpc's non-uniform
convolver (with and without IR swaps), the uniform one and zita-convolver.

Usage: scripts/plot_convolve.py docs/data/convolve.json docs/images/convolve.png
"""
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: plot_convolve.py IN.json OUT.png")
    with open(sys.argv[1]) as f:
        data = json.load(f)
    names = []
    for c in data["cases"]:
        if c["name"] not in names:
            names.append(c["name"])
    fig, axes = plt.subplots(1, len(names), figsize=(4 * len(names), 3.6), sharey=True)
    for ax, name in zip(axes, names):
        cases = [c for c in data["cases"] if c["name"] == name]
        blocks = sorted({c["block"] for c in cases})

        def series(pick):
            ys = []
            for b in blocks:
                vals = [pick(c) for c in cases if c["block"] == b]
                vals = [v for v in vals if v is not None]
                ys.append(vals[0] if vals else float("nan"))
            return ys

        def mean(c, key, swap):
            if (c["swap_interval_ms"] > 0) != swap or not c.get(key):
                return None
            return c[key].get("cpu_percent_mean")

        ax.plot(blocks, series(lambda c: mean(c, "zita", False)), "k-o", label="zita-convolver")
        ax.plot(blocks, series(lambda c: mean(c, "dpc", False)), "b-s", label="dpc, no swap")
        ax.plot(blocks, series(lambda c: mean(c, "dpc", True)), "r-^",
                label="dpc, IR swap every 66 ms")
        ax.plot(blocks, series(lambda c: mean(c, "dpc_uniform_no_swap", False)), "g--",
                label="dpc uniform (before), no swap")
        ax.set_xscale("log", base=2)
        ax.set_yscale("log")
        ax.set_xticks(blocks)
        ax.set_xticklabels([str(b) for b in blocks])
        ax.set_title(name)
        ax.set_xlabel("block size (samples, 48 kHz)")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("CPU, % of one core (all threads)")
    axes[0].legend(fontsize=7)
    fig.suptitle("dpc-bench convolve: one run on a loaded 2-core machine (compare ratios)",
                 fontsize=9)
    fig.tight_layout()
    fig.savefig(sys.argv[2], dpi=110)


if __name__ == "__main__":
    main()
