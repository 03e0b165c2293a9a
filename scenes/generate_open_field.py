#!/usr/bin/python3
"""Generates the outdoor scene: scenes/open_field.obj and scenes/open_field.json.
Deterministic (same output every run).

A 2000 x 2000 m ground plane (y = 0 up; x, z -1000..1000) with two closed buildings: A
(x 10..40, y 0..25, z -20..20) and B (x -30..-10, y 0..15, z -40..-20). A talker stands at
(0, 1.6, 0) in front of A's west face. The listener walks along z = 22 from x = 45 (behind A:
the direct sound only arrives diffracted round A's north-west vertical edge at x = 10, z = 20)
to x = 2 (in view) over 12 s, crossing the shadow boundary at x = 11.

The scene is open (the ground's boundary edges), so the IR synthesis' reflection-density law
runs on the bounding box, 10^8 m^3; the Dirac sequence's density floor keeps early
reflections early there (docs/validation.md, "Open scenes").

Usage: generate_open_field.py [OUT_FOLDER]   (default: this script's folder)
"""
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from objfile import ObjMesh  # noqa: E402

HALF = 1000.0  # ground half-width, m
BUILDINGS = [  # (x0, x1, height, z0, z1)
    (10.0, 40.0, 25.0, -20.0, 20.0),
    (-30.0, -10.0, 15.0, -40.0, -20.0),
]
out = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.abspath(__file__))

mesh = ObjMesh()
# Ground, facing up (+y).
mesh.quad((-HALF, 0, -HALF), (-HALF, 0, HALF), (HALF, 0, HALF), (HALF, 0, -HALF), "ground")
for x0, x1, h, z0, z1 in BUILDINGS:
    # Closed boxes (8 shared corners), faces outward (the floor face too, so each box is
    # watertight).
    mesh.box(x0, x1, 0, h, z0, z1, ["facade"] * 4 + ["roof", "facade"])

mesh.write(os.path.join(out, "open_field.obj"),
           "# dpc open field: 2 km ground plane and two buildings, written by "
           "generate_open_field.py. Materials are defined in open_field.json.\n")

scene = {
    "_comment": "Outdoor scene (scenes/generate_open_field.py): 2 km ground plane, two "
                "buildings. The listener walks from behind building A (direct sound only "
                "diffracted round its corner) into view of the talker, crossing the shadow "
                "boundary at x = 11. Absorption values are illustrative, not from a measured "
                "table.",
    "mesh": "open_field.obj",
    "materials": {
        "ground": {
            "source": "illustrative: short grass on firm soil, absorbing more at high "
                      "frequencies",
            "absorption": [0.05, 0.05, 0.1, 0.2, 0.3, 0.4, 0.5, 0.5],
            "scattering": 0.5,
        },
        "facade": {
            "source": "illustrative: brick and glass facade",
            "absorption": [0.03, 0.03, 0.03, 0.04, 0.05, 0.07, 0.07, 0.07],
            "scattering": 0.3,
        },
        "roof": {
            "source": "illustrative: flat roof",
            "absorption": [0.05, 0.05, 0.05, 0.05, 0.05, 0.05, 0.05, 0.05],
            "scattering": 0.2,
        },
    },
    "sources": [
        {"name": "talker", "position": [0.0, 1.6, 0.0], "signal": "signals/speech.wav",
         "gain_db": 0, "loop": True}
    ],
    "listener": {
        "position": [45.0, 1.6, 22.0],
        "radius": 0.5,
        "trajectory": [
            {"t": 0.0, "position": [45.0, 1.6, 22.0]},
            {"t": 12.0, "position": [2.0, 1.6, 22.0]},
        ],
    },
    "propagation": {
        "rays_per_frame": 4096,
        "max_order": 50,
        "patch_size": 1.0,
        "cache_tau": 1.0,
        "frame_rate": 15,
        "ir_length": 1.5,
        "seed": 1,
        "estimator": "dpc",
        "dpc_weighting": "ema",
        "temperature": 20,
        "humidity": 50,
        "air_absorption": True,
    },
    "audio": {"sample_rate": 48000, "block_size": 512},
}
with open(os.path.join(out, "open_field.json"), "w") as f:
    json.dump(scene, f, indent=2)
    f.write("\n")
