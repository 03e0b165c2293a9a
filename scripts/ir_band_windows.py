#!/usr/bin/python3
"""One IR's octave-band energy in time windows against its energy response's, with no filter of dpc.

Reads dpc-demo's `--ir-out` WAV (mono: one channel per source) and `--er-out` CSV of the same
render. Per octave 125 Hz - 1 kHz it filters the IR by FFT with zero-phase octave masks written
here (1 inside the octave, cos^2 crossovers 1/3 octave wide centred on the octave edges, -3 dB
there) and divides the squared output by the mask's impulse energy, so that a white band reads
its band value (dpc's band values are spectral densities relative to a unit impulse). The
response's band values per 1 ms bin (and its direct sound on its sample) are spread over time by
the same mask's squared impulse response, so both carry the filter's time spread; the response's
within-band tilt is not modelled, so where a neighbouring octave decays much more slowly the
late windows read the IR high. Windows from the direct sound t0: t0 +- 2 ms, t0 - 5 ms .. t0 +
50 ms, .. t0 + 80 ms, t0 + 80 ms .. end, and 10 ms windows; per window the IR's energy over the
response's in dB, mean [standard deviation] over all source-listener pairs given, and C80 of both.

Usage: /usr/bin/python3 scripts/ir_band_windows.py IR.wav:ER.csv [IR.wav:ER.csv ...]
(used for BRAS CR2 in docs/validation.md, "Measured rooms").
"""
import sys
import warnings

import numpy as np
import scipy.io.wavfile as wavfile

BANDS = [63, 125, 250, 500, 1000, 2000, 4000, 8000]
SHOWN = (1, 2, 3, 4)  # 125 Hz .. 1 kHz
FS = 48000


def masks(n, d=1 / 6):
    """Amplitude masks per octave on the n-point FFT's bins (63 Hz down to 0, 8 kHz up to
    Nyquist); the power masks sum to 1."""
    f = np.fft.rfftfreq(n, 1 / FS)
    out = []
    for i, fc in enumerate(BANDS):
        x = np.log2(np.maximum(f, 1e-9) / fc)
        up = np.ones_like(x) if i == 0 else np.clip((x + 0.5 + d) / (2 * d), 0, 1)
        down = np.ones_like(x) if i == len(BANDS) - 1 else np.clip((0.5 + d - x) / (2 * d), 0, 1)
        out.append(np.sin(np.pi / 2 * up) * np.sin(np.pi / 2 * down))
    return out


def read_er(path):
    """Per source: (direct time, direct bands) or None, and the 1 ms bins (rows x 8)."""
    per = {}
    with open(path) as f:
        for line in f:
            if not line[0].isdigit():
                continue
            r = line.strip().split(',')
            src = per.setdefault(int(r[0]), {'direct': None, 'bins': []})
            v = np.array([float(x) for x in r[3:]])
            if r[1] == 'direct':
                src['direct'] = (float(r[2]), v)
            else:
                src['bins'].append(v)
    return per


def expected(src, n, m):
    """The response's band energy per sample spread by the masks' squared impulse responses."""
    bins = np.array(src['bins'])
    per = FS // 1000
    e = np.zeros((len(BANDS), n))
    k = min(len(bins) * per, n)
    e[:, :k] = np.repeat(bins.T / per, per, axis=1)[:, :k]
    if src['direct'] is not None:
        e[:, int(round(src['direct'][0] * FS))] += src['direct'][1]
    out = []
    for b, mask in enumerate(m):
        h = np.fft.irfft(mask, n)
        kernel = np.fft.rfft(h ** 2 / np.sum(h ** 2), n)
        out.append(np.fft.irfft(np.fft.rfft(e[b], n) * kernel, n))
    return np.array(out)


def windows(t0):
    w = {'direct +-2 ms': (t0 - .002, t0 + .002), '0-50 ms': (t0 - .005, t0 + .05),
         '0-80 ms': (t0 - .005, t0 + .08), '80 ms-end': (t0 + .08, 1e9)}
    w.update({f'{10 * k}-{10 * k + 10} ms': (t0 + .01 * k, t0 + .01 * (k + 1)) for k in range(10)})
    return w


def pair(ir, src, m, n):
    """Per shown band and window: (IR energy, response energy)."""
    spectrum = np.fft.rfft(ir, n)
    e = expected(src, n, m)
    t0 = src['direct'][0] if src['direct'] is not None else 0.0
    out = {}
    for b in SHOWN:
        h = np.fft.irfft(m[b], n)
        p = np.fft.irfft(spectrum * m[b], n) ** 2 / np.sum(h ** 2)
        out[b] = {}
        for name, (a, z) in windows(t0).items():
            i0, i1 = max(0, int(a * FS)), min(len(ir), int(z * FS))
            out[b][name] = (p[i0:i1].sum(), e[b][i0:i1].sum())
    return out


def main():
    if len(sys.argv) < 2 or any(':' not in a for a in sys.argv[1:]):
        sys.exit(__doc__)
    warnings.filterwarnings('ignore', category=wavfile.WavFileWarning)
    results = []
    for arg in sys.argv[1:]:
        wav, csv = arg.split(':', 1)
        rate, ir = wavfile.read(wav)
        if rate != FS:
            sys.exit(f'ir_band_windows.py: {wav}: {rate} Hz, expected {FS}')
        ir = ir.reshape(len(ir), -1).astype(float)
        er = read_er(csv)
        n = 1 << int(np.ceil(np.log2(len(ir) + FS)))
        m = masks(n)
        results += [pair(ir[:, s], er[s], m, n) for s in range(ir.shape[1])]
    for b in SHOWN:
        print(f'{BANDS[b]} Hz, {len(results)} pairs: IR over response (dB), mean [sd]')
        for name in results[0][b]:
            v = [10 * np.log10(r[b][name][0] / r[b][name][1]) for r in results]
            print(f'  {name:14s} {np.mean(v):+6.2f} [{np.std(v):.2f}]')
        c80 = np.array([[10 * np.log10(r[b]['0-80 ms'][i] / r[b]['80 ms-end'][i]) for i in (0, 1)]
                        for r in results])
        print(f'  C80 IR {c80[:, 0].mean():+.2f} dB, response {c80[:, 1].mean():+.2f} dB, '
              f'difference {np.mean(c80[:, 0] - c80[:, 1]):+.2f} dB')


if __name__ == '__main__':
    main()
