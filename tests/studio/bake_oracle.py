#!/usr/bin/env python3
"""The browser test's oracle for /api/bake (tests/studio/bake_check.mjs): a bake file read with
h5py alone (none of dpc's code), printed as JSON on stdout, and matplotlib's viridis ends.

  {"positions": [[x, y, z] per probe], "done": [0/1 per probe], "columns": [the bake's
   parameter_columns], "parameters": [probe][source][row][column], "sti": [probe][source],
   "viridis": [[r, g, b] at 0, [r, g, b] at 1]}

Floats are the stored float32 values widened to double and printed by Python's repr (the
shortest text that reads back as the same double), so they compare exactly; NaN and inf
print as null. Usage: bake_oracle.py BAKE.h5
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


def main():
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
