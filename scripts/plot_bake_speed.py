#!/usr/bin/env python3
"""Bake throughput from `dpc-bench bake` JSON: probes per second against probe count for each
way of running (1 process with 1 or 2 threads, mpirun -np 2), and the gather's predicted
scaling with the number of ranks, min(ranks / probe seconds, 1 / commit seconds), with the
measured runs on it.

    dpc-bench bake scenes/shoebox.json > docs/bench/bake-shoebox.json
    scripts/plot_bake_speed.py docs/bench/bake-shoebox.json docs/images/bake_speed.png
"""
import argparse
import json
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def ranks_of(run):
    """Workers of a run: threads or MPI ranks (each rank runs one thread)."""
    mode = run["mode"]
    if mode.startswith("mpirun"):
        return run["processes"]
    return 2 if "2 threads" in mode else 1


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("bench_json", help="output of dpc-bench bake")
    parser.add_argument("out", help="PNG to write")
    args = parser.parse_args()
    try:
        with open(args.bench_json, encoding="utf-8") as f:
            data = json.load(f)
        runs = data["runs"]
        prediction = data["prediction"]
    except (OSError, ValueError, KeyError) as e:
        sys.exit(f"plot_bake_speed.py: {args.bench_json}: {e}")

    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2))
    for mode in sorted({r["mode"] for r in runs}):
        rs = sorted((r for r in runs if r["mode"] == mode), key=lambda r: r["probes"])
        left.plot([r["probes"] for r in rs], [r["probes_per_second"] for r in rs], "o-",
                  label=mode)
    left.set_xscale("log")
    left.set_xlabel("probes in the bake")
    left.set_ylabel("probes per second")
    left.set_ylim(bottom=0)
    left.set_title(f"{data.get('scene', '')}: {data.get('rays')} rays x {data.get('frames')} "
                   "frames per probe", fontsize=9)
    left.grid(True, alpha=0.3)
    left.legend(fontsize=8)

    # The model drawn densely from its parameters (the JSON's curve holds a few points only).
    probe_s = prediction["probe_seconds_one_thread"]
    commit_s = prediction["commit_seconds_per_probe"]
    top = max(p["ranks"] for p in prediction["curve"])
    ranks = [2 ** (k / 8) for k in range(int(8 * math.log2(top)) + 1)]
    right.loglog(ranks, [min(r / probe_s, 1 / commit_s) for r in ranks], "-", color="grey",
                 label=f"predicted: min(ranks / {probe_s:.3f} s, 1 / {commit_s * 1e3:.2f} ms)")
    largest = max(r["probes"] for r in runs)
    measured = [r for r in runs if r["probes"] == largest]
    right.loglog([ranks_of(r) for r in measured], [r["probes_per_second"] for r in measured],
                 "o", label=f"measured, {largest} probes")
    level = prediction.get("level")
    if level:
        right.axvline(level["ranks"], color="C3", ls=":",
                      label=f"{level['probes']:.0f}-probe level on {level['nodes']:.0f} nodes: "
                            f"{level['hours'] * 3600:.0f} s")
    right.set_xlabel("ranks (one thread each)")
    right.set_ylabel("probes per second")
    right.set_title("scaling of the gather to one writer", fontsize=9)
    right.grid(True, which="both", alpha=0.3)
    right.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(args.out, dpi=110)


if __name__ == "__main__":
    main()
