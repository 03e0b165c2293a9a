#!/usr/bin/python3
"""Plots `dpc-bench load` JSON: load time of a generated terrain against its triangle count,
stage by stage, and the diffraction edge finder against the exhaustive search it replaced
(each candidate edge tested against every triangle; measured with that code on the same
terrains).

Usage: scripts/plot_load.py docs/data/load.json docs/data/load-exhaustive-edges.json \\
           docs/images/load-time.png
"""
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

STAGES = [("load_scene_ms", "OBJ + scene (loadScene)", "tab:blue"),
          ("geometry_ms", "patch geometry", "tab:green"),
          ("embree_ms", "Embree BVH", "tab:purple"),
          ("edge_finding_ms", "diffraction edges", "tab:red")]


def main():
    if len(sys.argv) != 4:
        sys.exit("usage: plot_load.py LOAD.json EXHAUSTIVE.json OUT.png")
    with open(sys.argv[1]) as f:
        sizes = json.load(f)["sizes"]
    with open(sys.argv[2]) as f:
        before = json.load(f)["sizes"]
    tris = [s["triangles"] for s in sizes]
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    ax.plot(tris, [s["total_ms"] / 1000 for s in sizes], "k-o", label="total load")
    for key, label, color in STAGES:
        ax.plot(tris, [s[key] / 1000 for s in sizes], "-", color=color, marker=".", label=label)
    ax.plot([s["triangles"] for s in before], [s["edge_finding_ms"] / 1000 for s in before],
            "--x", color="tab:red", label="diffraction edges, exhaustive search")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("triangles (terrain of testing/terrain.h, 16 panels)")
    ax.set_ylabel("seconds")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title("dpc-bench load: one run each on a shared 2-core machine", fontsize=9)
    fig.tight_layout()
    fig.savefig(sys.argv[3], dpi=110)


if __name__ == "__main__":
    main()
