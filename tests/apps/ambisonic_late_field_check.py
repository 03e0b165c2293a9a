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
    for f in failures:
        print("FAIL:", f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
