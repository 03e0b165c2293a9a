#!/usr/bin/env python3
"""The browser test's oracle for /api/bake (tests/studio/bake_check.mjs): a bake file read with
h5py alone (none of dpc's code), printed as JSON on stdout, and matplotlib's viridis ends.

  {"positions": [[x, y, z] per probe], "done": [0/1 per probe], "columns": [the bake's
   parameter_columns], "parameters": [probe][source][row][column], "sti": [probe][source],
   "viridis": [[r, g, b] at 0, [r, g, b] at 1]}

Floats are the stored float32 values widened to double and printed by Python's repr (the
shortest text that reads back as the same double), so they compare exactly; NaN and inf
print as null. Usage: bake_oracle.py BAKE.h5

bake_oracle.py BAKE.h5 --response PROBE SOURCE: the energy response a player of the bake uses
at that probe, as docs/bake-format.md ("Reading a bake", the late response) and docs/bake.md
define it: `energy` with the direct sound (`direct/`) taken out of the bin of its arrival
(bin floor(delay / 1 ms)), then every exact early path taken out (`early/energy`, bin by bin),
each clamped at 0, in float32, then the direct sound added back into its bin (the studio's
response carries it; the exact paths, which the player adds live, are not in it):

  {"response": [[8 floats] per 1 ms bin], "directBin": k, "direct": [8 floats],
   "directDelay": s, "earlyCount": n, "earlyFound": n}
"""
import json
import math
import sys

import h5py
import numpy as np


def plain(a):
    """Nested lists of Python floats, non-finite values as None."""
    if isinstance(a, np.ndarray):
        return [plain(x) for x in a]
    v = float(a)
    return v if math.isfinite(v) else None


def viridis_ends():
    try:
        import matplotlib
        cmap = matplotlib.colormaps["viridis"]
        return [list(cmap(0.0)[:3]), list(cmap(1.0)[:3])]
    except ImportError:  # matplotlib's published ends, #440154 and #fde725
        return [[0.267004, 0.004874, 0.329415], [0.993248, 0.906157, 0.143936]]


def remove(row, delay, intensity):
    """Takes one arrival out of its bin (float32, clamped at 0), as the bake's reader does."""
    k = float(delay) / 1e-3
    if 0.0 <= k < len(row):
        row[int(k)] = np.maximum(np.float32(0), row[int(k)] - intensity)


def response(path, p, s):
    with h5py.File(path, "r") as f:
        row = f["energy"][p, s].astype(np.float32)
        delay = f["direct/delay_s"][p, s]
        direct = f["direct/energy"][p, s].astype(np.float32)
        count, found = int(f["early/count"][p, s]), int(f["early/found"][p, s])
        exact = f["early/energy"][p, s].astype(np.float32)
    remove(row, delay, direct)
    row = np.maximum(np.float32(0), row - exact)
    k = int(float(delay) / 1e-3)
    row[k] = row[k] + direct
    return {"response": plain(row), "directBin": k, "direct": plain(direct),
            "directDelay": float(delay), "earlyCount": count, "earlyFound": found}


def main():
    if len(sys.argv) == 5 and sys.argv[2] == "--response":
        json.dump(response(sys.argv[1], int(sys.argv[3]), int(sys.argv[4])), sys.stdout)
        return
    with h5py.File(sys.argv[1], "r") as f:
        columns = f.attrs["parameter_columns"]
        columns = columns.decode() if isinstance(columns, bytes) else str(columns)
        out = {"positions": plain(f["probes/position"][()]),
               "done": [int(d) for d in f["probes/done"][()]],
               "columns": columns.split(","),
               "parameters": plain(f["parameters"][()]),
               "sti": plain(f["sti"][()]),
               "viridis": viridis_ends()}
    json.dump(out, sys.stdout)


if __name__ == "__main__":
    main()
