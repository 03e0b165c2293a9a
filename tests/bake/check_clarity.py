#!/usr/bin/env python3
"""C50 and C80 of a bake, checked against an oracle that computes them itself (NumPy and h5py,
none of dpc's analysis code) from each probe's own stored energy response.

ISO 3382-1, A.2.4: C_te = 10 lg(E[t0, t0 + te) / E[t0 + te, inf)), t0 the arrival of the direct
sound (ISO 3382-1 A.3.4; an IR's analysis finds it at the direct pulse): `direct/delay_s` when the
probe's direct sound has energy and its arrival lies in the band's first non-empty 1 ms bin of the
energy histogram (that bin then holds [t0, its end)), else that bin's start. te = 50 ms and 80 ms;
the bin holding t0 + te is split in proportion to time. The broadband row weighs the 8 bands
by their shares of a white spectrum at 48 kHz (a band value is a spectral density). The bake's `parameters` (columns C50, C80) and the map CSV's rows must both agree with it
within TOLERANCE_DB.

Tolerance: the oracle sums the stored float32 energies, dpc the double-precision means they
were rounded from (relative error 6e-8 per bin); 0.01 dB is 10^4 times that effect, and a
tenth of the smallest gap between C50 and C80 this check relies on to see them swapped (it
reports that gap). Usage: check_clarity.py BAKE.h5 MAP.csv; exit 0 when every value agrees.
"""
import csv
import sys

import h5py
import numpy as np

TOLERANCE_DB = 0.01
BANDS = ["63", "125", "250", "500", "1000", "2000", "4000", "8000", "broadband"]


def clarity(energy, limit_ms, direct_ms):
    """C in dB of one energy histogram (1 ms bins): early [t0, t0 + limit), late the rest;
    direct_ms the direct sound's arrival (ms) or None."""
    e = np.asarray(energy, dtype=np.float64)
    nonzero = np.flatnonzero(e > 0)
    if nonzero.size == 0:
        return float("nan")
    first = int(nonzero[0])
    t0 = direct_ms if direct_ms is not None and first <= direct_ms < first + 1 else float(first)
    end = t0 + limit_ms
    last = int(np.floor(end))  # the bin holding t0 + limit
    early = e[first:last].sum() + (end - last) * (e[last] if last < e.size else 0.0)
    late = e.sum() - early
    with np.errstate(divide="ignore"):
        return float(10 * np.log10(early / late))


def white_shares(rate=48000.0):
    """Each octave band's share of a white spectrum from 0 Hz to Nyquist: its span between the
    edges fc / sqrt 2 and fc sqrt 2 (exact base-2 centres), 63 Hz from 0 Hz, 8 kHz to Nyquist."""
    centres = 1000.0 * 2.0 ** (np.arange(8) - 4)
    edges = np.concatenate(([0.0], centres[:-1] * np.sqrt(2), [rate / 2]))
    return np.diff(edges) / (rate / 2)


def oracle(energy_ps, direct_ms):
    """[row][C50, C80] for one probe and source ([bins][8] energy): 8 bands, then broadband
    (the bands weighted by their white shares: a band value is a spectral density)."""
    rows = [energy_ps[:, b] for b in range(8)] + [energy_ps @ white_shares()]
    return np.array([[clarity(r, 50, direct_ms), clarity(r, 80, direct_ms)] for r in rows])


def agree(stored, expected):
    if not np.isfinite(expected):
        return not np.isfinite(stored)
    return abs(stored - expected) <= TOLERANCE_DB


def main(bake_path, map_path):
    f = h5py.File(bake_path, "r")
    assert f.attrs["bin_seconds"] == 0.001
    columns = f.attrs["parameter_columns"].decode().split(",")
    c50, c80 = columns.index("C50"), columns.index("C80")
    energy = f["energy"][...]
    delay = f["direct/delay_s"][...]
    direct_energy = f["direct/energy"][...]
    params = f["parameters"][...]
    done = f["probes/done"][...]
    csv_values = {}
    with open(map_path) as m:
        for row in csv.DictReader(m):
            key = (int(row["probe"]), int(row["source"]), row["parameter"], row["band"])
            csv_values[key] = float(row["value"])
    checked = bad = 0
    gap = float("inf")
    for p in np.flatnonzero(done):
        for s in range(energy.shape[1]):
            heard = direct_energy[p, s].sum() > 0
            want = oracle(energy[p, s], 1e3 * float(delay[p, s]) if heard else None)
            for r, band in enumerate(BANDS):
                for k, name, col in ((0, "C50", c50), (1, "C80", c80)):
                    expected = want[r, k]
                    for where, got in (("parameters", params[p, s, r, col]),
                                       ("map", csv_values[(p, s, name, band)])):
                        checked += 1
                        if not agree(got, expected):
                            bad += 1
                            if bad <= 5:
                                print(f"{where}: probe {p} source {s} {name} {band}: "
                                      f"{got:.4f} dB, the oracle {expected:.4f} dB")
                if np.all(np.isfinite(want[r])):
                    gap = min(gap, abs(want[r, 1] - want[r, 0]))
    print(f"check_clarity: {checked} values, {bad} disagree by more than {TOLERANCE_DB} dB; "
          f"smallest |C80 - C50| {gap:.3f} dB")
    if gap <= 2 * TOLERANCE_DB:
        print("check_clarity: C50 and C80 too close to tell apart")
        return 1
    return 1 if bad or checked == 0 else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], sys.argv[2]))
