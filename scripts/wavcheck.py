#!/usr/bin/python3
"""Checks a WAV file for silence and non-finite samples. Exit 1 if silent or not finite.

Usage: scripts/wavcheck.py FILE.wav [--min-rms 1e-4]
"""
import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from plot_render import read_wav  # noqa: E402

import numpy as np  # noqa: E402

ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
ap.add_argument("wav")
ap.add_argument("--min-rms", type=float, default=1e-4)
a = ap.parse_args()
x, fs = read_wav(a.wav)
nonfinite = int(np.count_nonzero(~np.isfinite(x)))
rms = float(np.sqrt(np.mean(np.square(np.nan_to_num(x)))))
print(f"{a.wav}: {x.shape[0]} ch, {x.shape[1] / fs:.2f} s at {fs} Hz, rms {rms:.3g}, "
      f"peak {float(np.max(np.abs(np.nan_to_num(x)))):.3g}, non-finite {nonfinite}")
sys.exit(1 if nonfinite or rms < a.min_rms else 0)
