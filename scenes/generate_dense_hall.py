#!/usr/bin/python3
"""Generates the many-source benchmark room: scenes/dense_hall.obj and scenes/dense_hall.json.
Deterministic (same output every run).

One 20 x 15 x 4 m room (x 0..20, y 0..4 up, z 0..15): a reception or exhibition hall with a
concrete floor, plasterboard walls, an absorbing tile ceiling, two rows of four pillars and
twelve tables (closed boxes, wood). 64 static sources stand on an 8 x 8 grid at 1.5 m (talkers,
-6 dB each); the listener (radius 0.5 m) walks a loop between the pillar rows. Everything
shares one room, so every source's paths reach the listener through the same reverberant
field: the dense case of many-source propagation (docs/performance.md, "Many sources"), where
every pair's cache holds a full room's paths.

Usage: generate_dense_hall.py [OUT_FOLDER] [--grid N]
  OUT_FOLDER  default: this script's folder (created if missing)
  --grid N    N x N talkers instead of 8 x 8 (N even; 16: the 256-source case), written as
              dense_hall_N.json / .obj; the signal path is relative to OUT_FOLDER
"""
import argparse
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from objfile import ObjMesh  # noqa: E402

LX, LY, LZ = 20.0, 4.0, 15.0
PILLARS = [(x, z) for x in (5.0, 10.0, 15.0, 20.0 - 2.5) for z in (5.0, 10.0)][:8]
PILLAR_HALF = 0.25
TABLES = [(3.0 + 3.0 * i, 2.2 + 10.6 * j) for i in range(6) for j in range(2)]
TABLE_HALF, TABLE_HEIGHT = 0.6, 0.75
here = os.path.dirname(os.path.abspath(__file__))
ap = argparse.ArgumentParser()
ap.add_argument('out', nargs='?', default=here)
ap.add_argument('--grid', type=int, default=8)
args = ap.parse_args()
out, grid = args.out, args.grid
if grid < 2 or grid % 2:
    ap.error("--grid: %d is not an even number >= 2 (half the rows stand on each side of the "
             "listener's lane)" % grid)
name = 'dense_hall' if grid == 8 else 'dense_hall_%d' % grid
os.makedirs(out, exist_ok=True)

mesh = ObjMesh()
mesh.box(0.0, LX, 0.0, LY, 0.0, LZ, ["wall", "wall", "wall", "wall", "ceiling", "floor"],
    inward=True)
for x, z in PILLARS:
    mesh.box(x - PILLAR_HALF, x + PILLAR_HALF, 0.0, LY, z - PILLAR_HALF, z + PILLAR_HALF, "pillar")
for x, z in TABLES:
    mesh.box(x - TABLE_HALF, x + TABLE_HALF, 0.0, TABLE_HEIGHT, z - TABLE_HALF, z + TABLE_HALF,
             "table")

mesh.write(os.path.join(out, name + ".obj"),
           "# dpc dense hall: one 20 x 15 x 4 m room, 8 pillars, 12 tables, written by "
           "generate_dense_hall.py. Materials are defined in dense_hall.json.\n")

sources = []
signal = os.path.relpath(os.path.join(here, "signals", "speech.wav"), out)
# Columns at x 1.5..18.5; half the rows at z 1.2..6.6, half at 8.4..13.8, so that the
# listener's lane (z 7.3..7.7) stays 0.7 m clear of every talker (grid even, >= 2).
half = grid // 2
rows = [1.2 + k * 5.4 / max(half - 1, 1) for k in range(half)]
rows += [z + 7.2 for z in rows]
for i in range(grid):
    for j, z in enumerate(rows):
        sources.append({
            "name": "talker %d.%d" % (i, j),
            "position": [round(1.5 + i * 17.0 / (grid - 1), 3), 1.5, round(z, 3)],
            "signal": signal,
            "gain_db": -6,
            "loop": True,
        })
loop = [[2.0, 7.3], [18.0, 7.3], [18.0, 7.7], [2.0, 7.7], [2.0, 7.3]]
t, trajectory = 0.0, []
for k, (x, z) in enumerate(loop):
    if k:
        px, pz = loop[k - 1]
        t += (abs(x - px) + abs(z - pz)) / 1.2  # walking at 1.2 m/s
    trajectory.append({"t": round(t, 3), "position": [x, 1.6, z]})
scene = {
    "_comment": "Many-source benchmark room (scenes/generate_dense_hall.py): 20 x 15 x 4 m, "
                "64 static talkers on an 8 x 8 grid, the listener walking a loop between the "
                "pillar rows (and between two rows of talkers, 0.7 m clear of them) at "
                "1.2 m/s. Materials: entries of the materials library (materials/library.json).",
    "mesh": name + ".obj",
    "materials": {
        "floor": "concrete_floor",
        "wall": {"library": "plasterboard_on_frame", "scattering": 0.3},
        "ceiling": "acoustic_tile_fissured",
        "pillar": {"library": "concrete_rough", "scattering": 0.3},
        "table": {"library": "wooden_lining_12mm", "scattering": 0.5},
    },
    "listener": {"position": trajectory[0]["position"], "radius": 0.5,
                 "trajectory": trajectory, "loop": True},
    "sources": sources,
    "propagation": {"rays_per_frame": 4096, "max_order": 200, "exact_order": 3,
                    "cache_tau": 1.0, "frame_rate": 15, "ir_length": 2.0, "seed": 1,
                    "tracing": "auto"},
    "audio": {"sample_rate": 48000, "block_size": 512},
}
with open(os.path.join(out, name + ".json"), "w") as f:
    json.dump(scene, f, indent=1)
    f.write("\n")
