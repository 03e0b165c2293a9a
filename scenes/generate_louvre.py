#!/usr/bin/python3
"""Generates the louvre scene: scenes/louvre.obj and scenes/louvre.json.
Deterministic (same output every run).

A 40 x 40 m ground plane (y = 0 up) and, across it at x = 0, a slatted screen (a fence, a
louvre): 50 vertical slats 1 cm thick (z) and 10 cm deep (x), 2 m tall, 2 cm apart, from
z = -0.75 to 0.75 m. A talker stands 3 m before it at (-3, 1.2, 0); the listener walks 3 m
behind it along x = 3 from z = -0.3 to 0.3 over 6 s, the line of sight now through a slot, now
on a slat. Slats 1 cm thick are under half a wavelength across in every octave band: the
screen passes what its slots' air passes (docs/estimators.md, small bodies), and its coupled
slits make it the costliest diffraction case per pair (`dpc-bench diffraction
scenes/louvre.json`).

Usage: generate_louvre.py [OUT_FOLDER]   (default: this script's folder)
"""
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from objfile import ObjMesh  # noqa: E402

HALF = 20.0  # ground half-width, m
SLATS, THICK, DEEP, GAP, TALL = 50, 0.01, 0.1, 0.02, 2.0  # count; m
out = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.abspath(__file__))

mesh = ObjMesh()
mesh.quad((-HALF, 0, -HALF), (-HALF, 0, HALF), (HALF, 0, HALF), (HALF, 0, -HALF), "ground")
z0 = -0.5 * (SLATS * THICK + (SLATS - 1) * GAP)
for n in range(SLATS):
    a, b = round(z0 + n * (THICK + GAP), 6), round(z0 + n * (THICK + GAP) + THICK, 6)
    mesh.box(-0.5 * DEEP, 0.5 * DEEP, 0, TALL, a, b, "wood")
mesh.write(os.path.join(out, "louvre.obj"),
           "# dpc louvre: a ground plane and a screen of 50 slats, written by "
           "generate_louvre.py. Materials are defined in louvre.json.\n")

scene = {
    "_comment": "A slatted screen on open ground (scenes/generate_louvre.py): 50 slats 1 cm "
                "thick, 2 cm apart. The listener walks behind it, the line of sight now "
                "through a slot, now on a slat. Absorption values are illustrative.",
    "mesh": "louvre.obj",
    "materials": {
        "ground": {"source": "illustrative: short grass",
                   "absorption": [0.05, 0.05, 0.1, 0.2, 0.3, 0.4, 0.5, 0.5],
                   "scattering": 0.5},
        "wood": {"source": "illustrative: painted timber",
                 "absorption": [0.1, 0.1, 0.08, 0.06, 0.06, 0.06, 0.06, 0.06],
                 "scattering": 0.2},
    },
    "sources": [
        {"name": "talker", "position": [-3.0, 1.2, 0.0], "signal": "signals/speech.wav",
         "gain_db": 0, "loop": True}
    ],
    "listener": {
        "position": [3.0, 1.2, -0.3],
        "radius": 0.1,
        "trajectory": [
            {"t": 0.0, "position": [3.0, 1.2, -0.3]},
            {"t": 6.0, "position": [3.0, 1.2, 0.3]},
        ],
    },
    "propagation": {
        "rays_per_frame": 4096,
        "max_order": 20,
        "patch_size": 0.5,
        "cache_tau": 1.0,
        "frame_rate": 15,
        "ir_length": 1.0,
        "seed": 1,
        "estimator": "dpc",
        "temperature": 20,
        "humidity": 50,
        "air_absorption": True,
    },
    "audio": {"sample_rate": 48000, "block_size": 512},
}
with open(os.path.join(out, "louvre.json"), "w") as f:
    json.dump(scene, f, indent=2)
    f.write("\n")
