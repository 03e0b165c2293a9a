#!/usr/bin/python3
"""Plots the live callback load against the JACK period (scripts/period_sweep.sh): per shipped
scene, the median, p99.9 and maximum callback duration in percent of the period, and writes
the table docs/live.md shows (JSON, for the record).

Usage: scripts/plot_periods.py out/periods docs/images/period-load.png docs/data/period-load.json
"""
import glob
import json
import os
import re
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def load(folder):
    """{scene: {period: stats}} from the sweep's --stats files."""
    runs = {}
    for path in glob.glob(os.path.join(folder, "*-p*.json")):
        m = re.match(r"(.+)-p(\d+)\.json$", os.path.basename(path))
        with open(path) as f:
            runs.setdefault(m.group(1), {})[int(m.group(2))] = json.load(f)
    return runs


def main():
    if len(sys.argv) != 4:
        sys.exit("usage: plot_periods.py SWEEP_DIR OUT.png OUT.json")
    runs = load(sys.argv[1])
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.2), sharey=True)
    table = []
    for i, scene in enumerate(sorted(runs)):
        periods = sorted(runs[scene])
        load_pct = [runs[scene][p]["callback_load_percent"] for p in periods]
        color = plt.cm.tab10(i)
        axes[0].plot(periods, [l["p99_9"] for l in load_pct], "-o", color=color, label=scene)
        axes[1].plot(periods, [l["max"] for l in load_pct], "-o", color=color, label=scene)
        for p, l in zip(periods, load_pct):
            s = runs[scene][p]
            table.append({"scene": scene, "period": p, "engine_block": s["engine_block_frames"],
                          "callbacks": s["callbacks"], "xruns": s["xruns"],
                          "median": l["median"], "p99_9": l["p99_9"], "max": l["max"],
                          "limited_frames": s["limiter"]["limited_frames"]})
    for ax, what in zip(axes, ("p99.9", "maximum")):
        ax.axhline(50, color="k", ls="--", lw=0.8, label="50 % of the period")
        ax.set_xscale("log", base=2)
        ax.set_xticks([64, 128, 256, 512, 1024], ["64", "128", "256", "512", "1024"])
        ax.set_xlabel("JACK period = engine block (frames at 48 kHz)")
        ax.set_title("callback duration, " + what)
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("% of the period")
    axes[1].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(sys.argv[2], dpi=110)
    with open(sys.argv[3], "w") as f:
        json.dump(table, f, indent=1)
    print("wrote", sys.argv[2], sys.argv[3])


if __name__ == "__main__":
    main()
