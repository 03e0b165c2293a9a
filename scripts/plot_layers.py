#!/usr/bin/env python3
"""Draws docs/images/layers.png: the layers of docs/design.md's table (what may include what)
beside the data flow of one propagation frame.

The layer graph is read from the same table that scripts/check-layers.py enforces, so the
picture cannot drift from the rule. Each layer stands on a row by its depth (the longest chain
of layers below it); a line joins a layer to each layer below it that it may include directly
(edges implied through another allowed layer are left out to keep the picture readable).
Usage: scripts/plot_layers.py [OUT.png]
"""
import importlib.util
import pathlib
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.patches import FancyArrowPatch, FancyBboxPatch  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parent.parent
SKIP = {"tests", "fuzz", "examples"}  # "any": drawn as a note, not as arrows to everything

# The data flow of one propagation frame, top to bottom: (stage, where it lives).
FRAME = [
    ("poses: trajectories at t, then host overrides", "runtime/"),
    ("world state (sources, listeners, objects)", "runtime/"),
    ("rays through the tracer (Embree)", "engine/"),
    ("path hits + diffraction edges", "engine/"),
    ("diffuse path cache (estimator)", "engine/"),
    ("energy response per band and 1 ms bin", "engine/"),
    ("IR synthesis per output channel", "synthesis/"),
    ("partition + FFT into a pooled IrSet", "runtime/"),
    ("lock-free queue  →  audio thread", "runtime/"),
    ("convolve, crossfade, mix a block", "audio/ + runtime/"),
    ("device · WAV file · host buffers", "audio/ · api/ · plugins/"),
]


def load_rules():
    spec = importlib.util.spec_from_file_location("check_layers", ROOT / "scripts" / "check-layers.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return {k: v for k, v in module.layer_table().items() if k not in SKIP}


def depths(rules):
    memo = {}

    def depth(layer):
        if layer not in memo:
            below = [d for d in rules.get(layer, ()) if d in rules and d != layer]
            memo[layer] = 1 + max((depth(d) for d in below), default=-1)
        return memo[layer]

    return {layer: depth(layer) for layer in rules}


def direct_edges(rules):
    """Allowed includes that are not implied by another allowed layer's allowance."""
    edges = []
    for layer, allowed in rules.items():
        allowed = {a for a in allowed if a in rules and a != layer}
        for target in allowed:
            implied = any(target in rules.get(other, ()) for other in allowed if other != target)
            if not implied:
                edges.append((layer, target))
    return edges


# Left-to-right order within a row, so that the include/ column stays on the right.
ORDER = ["audio", "common", "scene", "engine", "synthesis", "analysis", "testing", "runtime",
         "api", "apps", "bench", "include", "plugins"]


def finish_panel(ax, note_x, note_y, note, title, title_size):
    """A panel's grey note at its foot and its title; the panel spans x 0..1 and y from just
    below the note to 1, axes hidden."""
    ax.text(note_x, note_y, note, ha="center", fontsize=8, color="#555555")
    ax.set_title(title, fontsize=title_size)
    ax.set_xlim(0, 1)
    ax.set_ylim(note_y - 0.02, 1.0)
    ax.axis("off")


def draw_layers(ax, rules):
    level = depths(rules)
    rows = {}
    for layer, d in sorted(level.items(), key=lambda kv: (kv[1], ORDER.index(kv[0])
                                                          if kv[0] in ORDER else 99)):
        rows.setdefault(d, []).append(layer)
    boxes = {}
    for d, layers in rows.items():
        for i, layer in enumerate(layers):
            x, y = (i + 1) / (len(layers) + 1), 0.04 + 0.9 * d / max(rows)
            boxes[layer] = ax.text(x, y, layer + "/", ha="center", va="center", fontsize=9,
                                   zorder=3, bbox=dict(boxstyle="round,pad=0.5", fc="#dbe8f5",
                                                       ec="#2b5d8a"))
    ax.figure.canvas.draw()  # lays the boxes out, so that arrows can be clipped at their edges
    for layer, target in direct_edges(rules):
        a, b = boxes[layer], boxes[target]
        ax.add_patch(FancyArrowPatch(a.get_position(), b.get_position(), arrowstyle="-",
                                     color="#777777", lw=0.8, zorder=2,
                                     patchA=a.get_bbox_patch(), patchB=b.get_bbox_patch()))
    finish_panel(ax, 0.5, -0.03, "tests/, fuzz/, examples/ may include any layer",
                 "Layers: a line means the upper layer may include the lower\n"
                 "(lines implied through another layer left out)", 10)


def draw_frame(ax):
    n = len(FRAME)
    for i, (stage, where) in enumerate(FRAME):
        y = 1 - (i + 0.5) / n
        ax.add_patch(FancyBboxPatch((0.04, y - 0.032), 0.62, 0.064, boxstyle="round,pad=0.004",
                                    fc="#f5e6d3" if i < 8 else "#dff0d8", ec="#8a5a2b"))
        ax.text(0.35, y, stage, ha="center", va="center", fontsize=8.5)
        ax.text(0.70, y, where, ha="left", va="center", fontsize=8, color="#2b5d8a")
        if i + 1 < n:
            ax.add_patch(FancyArrowPatch((0.35, y - 0.033), (0.35, y - 1 / n + 0.033),
                                         arrowstyle="-|>", mutation_scale=9, color="#555555"))
    finish_panel(ax, 0.35, -0.01, "propagation thread (tan) · audio thread (green)", "One frame", 11)


def main():
    out = pathlib.Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "docs" / "images" / "layers.png"
    fig, (left, right) = plt.subplots(1, 2, figsize=(12, 6.5), gridspec_kw={"width_ratios": [1.1, 1]})
    fig.subplots_adjust(left=0.02, right=0.98, top=0.93, bottom=0.03, wspace=0.05)
    draw_layers(left, load_rules())
    draw_frame(right)
    fig.savefig(out, dpi=110)
    print(f"plot_layers: wrote {out}", file=sys.stderr)


if __name__ == "__main__":
    main()
