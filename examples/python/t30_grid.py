#!/usr/bin/python3
"""T30 per octave band over a grid of listener positions in a scene, from Python.

For each position on a grid at ear height, one dpc.Engine traces the scene with the listener
placed there (dpc.Engine.set_listener_pose) for a number of frames (the diffuse path cache
averages over them), then dpc.iso3382 analyses the impulse response; the script plots T30 per
band, one line per position, and writes the numbers as JSON beside the plot.

Usage (after `pip install --no-build-isolation .` or `cmake --install build --prefix
/usr/local`, or with PYTHONPATH=build/python):
    examples/python/t30_grid.py [SCENE.json] [OUT.png] [--frames N] [--rays N]
    (defaults: scenes/shoebox.json, t30-grid.png, 10 frames of 4096 rays; the grid is the
    shoebox's; docs/images/python-t30-grid.png is this script's output for the shoebox)
"""
import argparse
import json
import os

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import dpc  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
parser = argparse.ArgumentParser(description="T30 per band over a grid of listener positions")
parser.add_argument("scene", nargs="?", default=os.path.join(HERE, "..", "..", "scenes",
                                                             "shoebox.json"))
parser.add_argument("out", nargs="?", default="t30-grid.png")
# 10 frames of 4096 rays: the cache's window (tau = 1 s) is not yet full.
parser.add_argument("--frames", type=int, default=10, help="frames traced per position")
parser.add_argument("--rays", type=int, default=4096, help="rays per frame")
args = parser.parse_args()
scene, out = args.scene, args.out

# The shoebox is 10 x 7 m (x, z); a 3 x 3 grid 2 m or more from the walls, ears at 1.6 m.
GRID = [(x, 1.6, z) for x in (3.0, 5.0, 7.0) for z in (2.0, 3.5, 5.0)]


def t30_at(position):
    engine = dpc.Engine(scene, rays_per_frame=args.rays)
    engine.set_listener_pose(0, position)
    for _ in range(args.frames):
        engine.step()  # the GIL is released while tracing
    ir = engine.impulse_response(0)  # channels x samples; channel 0 is the pressure IR
    return dpc.iso3382(ir[0], engine.sample_rate)["t30"]


results = {f"{x:g},{z:g}": t30_at((x, y, z)).tolist() for x, y, z in GRID}

fig, ax = plt.subplots(figsize=(7, 4.2))
bands = np.array(dpc.BANDS_HZ)
for label, t30 in results.items():
    ax.semilogx(bands, t30, marker="o", lw=1, label=f"(x, z) = ({label}) m")
ax.set_xticks(bands)
ax.set_xticklabels([f"{b:g}" for b in bands])
ax.set_xlabel("octave band (Hz)")
ax.set_ylabel("T30 (s)")
ax.set_title(f"T30 per band at {len(GRID)} listener positions: {os.path.basename(scene)}")
ax.grid(True, which="both", alpha=0.3)
ax.legend(fontsize=7, ncol=3)
fig.tight_layout()
fig.savefig(out, dpi=110)
with open(os.path.splitext(out)[0] + ".json", "w") as f:
    json.dump({"scene": os.path.basename(scene), "frames": args.frames, "rays": args.rays,
               "bands_hz": dpc.BANDS_HZ, "t30_s": results}, f, indent=1)
print(f"wrote {out}")
