"""The late field of an AmbiX render is diffuse at every order: the late part's energy vector
is short and every order carries W's power (ctest ambisonic_late_field:check).

    ambisonic_late_field_check.py BUILD_DIR SOURCE_DIR

Renders scenes/shoebox.json (a 10 x 7 x 3 m room, scattering walls, the listener in the room's
middle part) with `dpc-demo --output ambisonics --ambisonic-order N --ir-out` for N = 1, 3, 5
and reads the talker's IR with SciPy alone (no dpc filter): the late part, from 80 ms after
the onset (the first sample within 20 dB of W's peak) to the end, broadband and in octave
bands (4th-order Butterworth, zero phase).

- Energy vector r = sum_t W (X, Y, Z) / sum_t W^2 (ACN: W 0, Y 1, Z 2, X 3; SN3D, where one
  plane wave from u gives r = u and |r| = 1): |r| <= 0.1 broadband and from 1 kHz up, the
  issue's criterion for a diffuse late field. In the 250 and 500 Hz octaves the estimate's own
  sampling deviation grows (about 2 B T independent samples in bandwidth B over the late
  part's T: 0.05 per component at 500 Hz over 0.9 s), so there the bound is 0.1 plus twice
  the deviation of |r| for an isotropic field, sqrt(3 / (2 B T)).
- Per-order power: in SN3D the channels of order n sum, for any direction, to the square of
  the plane wave's amplitude, so a late field of independent plane waves from any directions
  carries W's power at every order; a field left in W, or in the first order, or weighted
  like an early arrival (max-rE) does not. Within 1 dB of W's, per octave 250 Hz-4 kHz
  (3 sampling deviations of a power ratio at 250 Hz, 4.34 sqrt(2 / (2 B T)) dB each; less
  from 500 Hz up).
- Rank at order 5: the late part's channel covariance in N3D (each channel of order n times
  sqrt(2n + 1), where a diffuse field's covariance is white), each 10 ms window divided by its
  RMS over the channels so that the decay does not weight the estimate, per octave
  500 Hz-4 kHz. A diffuse field's sample covariance of p = 36 channels from n = 2 B T
  independent samples has its eigenvalues over their mean within the Marchenko-Pastur edges
  (1 -+ sqrt(p / n))^2 (0.63-0.84 at the lower edge here); the smallest must reach half that
  lower edge. The factor 2 leaves room for the room's own anisotropy and for the synthesis
  directions' Gram matrix (eigenvalues 0.83-1.12 for 72 directions; measured smallest
  0.58-0.61). A late field made of fewer independent directions than channels has rank below
  p: 32 directions at order 5 read 0.003-0.036.
Exit status 0 when every check passes; the figures are printed either way.
"""
import os
import subprocess
import sys
import tempfile
import warnings

import numpy as np
import scipy.io.wavfile as wavfile
import scipy.signal as signal

ORDERS = (1, 3, 5)
OCTAVES = (250, 500, 1000, 2000, 4000)
LATE_AFTER_ONSET = 0.08
RMAX = 0.1
ORDER_POWER_DB = 1.0
RANK_ORDER = 5
RANK_OCTAVES = (500, 1000, 2000, 4000)
RANK_WINDOW = 0.01


def render(build, source, order, work):
    ir = os.path.join(work, f"amb{order}.wav")
    subprocess.run([os.path.join(build, "apps", "dpc-demo"),
                    os.path.join(source, "scenes", "shoebox.json"),
                    "--offline", os.path.join(work, f"out{order}.wav"), "--duration", "1",
                    "--output", "ambisonics", "--ambisonic-order", str(order), "--ir-out", ir],
                   check=True, stdout=subprocess.DEVNULL)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the WAV's LIST chunk
        rate, x = wavfile.read(ir)
    return rate, x[:, :(order + 1) ** 2].astype(np.float64)  # the first source (the talker)


def late_start(rate, x):
    w = np.abs(x[:, 0])
    return int(np.argmax(w >= 0.1 * w.max())) + int(LATE_AFTER_ONSET * rate)


def octave(rate, x, centre):
    sos = signal.butter(4, [centre / np.sqrt(2), centre * np.sqrt(2)], "bandpass", fs=rate,
                        output="sos")
    return signal.sosfiltfilt(sos, x, axis=0)


def energy_vector(y):
    w = y[:, 0]
    return np.linalg.norm([np.dot(w, y[:, 3]), np.dot(w, y[:, 1]), np.dot(w, y[:, 2])]) / np.dot(w, w)


def order_powers_db(y, order):
    w = np.dot(y[:, 0], y[:, 0])
    return [10 * np.log10(np.sum(y[:, n * n:(n + 1) ** 2] ** 2) / w) for n in range(1, order + 1)]


def whitened_late_part(y, rate, order):
    """y's channels in N3D, each RANK_WINDOW window divided by its RMS over the channels."""
    n3d = np.sqrt([2 * int(np.sqrt(c)) + 1 for c in range((order + 1) ** 2)])
    win = int(RANK_WINDOW * rate)
    frames = (y[:len(y) // win * win] * n3d).reshape(-1, win, len(n3d))
    rms = np.sqrt(np.mean(frames ** 2, axis=(1, 2)))
    keep = rms > 1e-3 * rms.max()
    return (frames[keep] / rms[keep, None, None]).reshape(-1, len(n3d))


def check_rank(rate, x, order):
    failures = []
    start = late_start(rate, x)
    for centre in RANK_OCTAVES:
        y = whitened_late_part(octave(rate, x, centre)[start:], rate, order)
        eig = np.linalg.eigvalsh(y.T @ y / len(y))
        eig /= eig.mean()
        samples = 2 * (centre * np.sqrt(2) - centre / np.sqrt(2)) * len(y) / rate
        lower = (1 - np.sqrt(y.shape[1] / samples)) ** 2
        print(f"  rank, {centre} Hz: eigenvalues over their mean {eig.min():.3f}-{eig.max():.3f}, "
              f"Marchenko-Pastur lower edge {lower:.3f} (bound {lower / 2:.3f})")
        if eig.min() < lower / 2:
            failures.append(f"order {order} {centre} Hz smallest covariance eigenvalue "
                            f"{eig.min():.3f} < {lower / 2:.3f}")
    return failures


def check_order(rate, x, order):
    """The bands are filtered over the whole IR and then cut, so that no filter rings on the
    cut's step."""
    failures = []
    start = late_start(rate, x)
    late = x[start:]
    r = energy_vector(late)
    print(f"order {order}: broadband |r| {r:.3f}")
    if r > RMAX:
        failures.append(f"order {order} broadband |r| {r:.3f} > {RMAX}")
    seconds = len(late) / rate
    for centre in OCTAVES:
        y = octave(rate, x, centre)[start:]
        r = energy_vector(y)
        bound = RMAX if centre >= 1000 else RMAX + 2 * np.sqrt(3 / (2 * centre / np.sqrt(2) * seconds))
        powers = order_powers_db(y, order)
        print(f"  {centre} Hz: |r| {r:.3f} (bound {bound:.3f}), order power re W dB "
              + " ".join(f"{p:+.2f}" for p in powers))
        if r > bound:
            failures.append(f"order {order} {centre} Hz |r| {r:.3f} > {bound:.3f}")
        worst = max(abs(p) for p in powers)
        if worst > ORDER_POWER_DB:
            failures.append(f"order {order} {centre} Hz order power off W's by {worst:.2f} dB")
    return failures


def main():
    build, source = sys.argv[1], sys.argv[2]
    failures = []
    with tempfile.TemporaryDirectory() as work:
        for order in ORDERS:
            rate, x = render(build, source, order, work)
            failures += check_order(rate, x, order)
            if order == RANK_ORDER:
                failures += check_rank(rate, x, order)
    for f in failures:
        print("FAIL:", f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
