#!/usr/bin/python3
"""The synthesised impulse response against references that do not use dpc's own filters.

dpc's band analysis (dpc-analyze) shares the ISO octave filters the IR synthesis is levelled
on, so per-band agreement can hold by construction. This script measures the IR the way a
listener or a room-acoustics tool takes it, with its own NumPy code (no octave filters of
dpc's): broadband Schroeder decay, spectra by FFT, energy in time windows.

Rooms: boxes of four sizes (scenes/shoebox.obj scaled), one absorption on every surface and in
every band, air absorption off, so the energy response (ER) has the same value in every band
and a right IR has the direct sound's spectrum in its reverberant part too. Each room is
rendered diffuse (scattering 1) and specular (scattering 0), and anechoic (absorption 1) for
the direct sound alone. dpc-demo writes the last frame's IR (--ir-out) and ER (--er-out).

Per room and case it reports:
- broadband G, T30, EDT, C80 of the IR against the ER's broadband (the sum of its bands) and,
  for the specular case, against exact image sources (scripts/image_sources.py). G is on
  dpc's documented scale (squared IR samples sum to intensity re source power, 1/m^2), and
  as a level re the anechoic render's direct sound (calibration-free);
- out-of-band energy: the share of the reverberant part's energy (after the direct sound's
  first 5 ms) below 44 Hz and above 11.3 kHz, against the same shares of the direct sound;
- causality: energy earlier than r/c - 1 ms, broadband and per octave (FFT of that segment),
  in dB re the direct sound's energy in the same band;
- specular arrivals: for every image source up to order 3, the IR's energy within +-0.5 ms of
  its delay against the exact energy (relative to the direct sound), and the samples in the
  first 50 ms louder than the direct sound's peak where no image source lies within 0.5 ms.

Usage: /usr/bin/python3 scripts/validate_ir.py [--build build] [--rooms small mid hall large]
       [--rays 8192] [--seed 1] [--json docs/data/validation-ir.json] [--plot PNG] [--check]
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import image_sources  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
C = 343.0
NUM_BANDS = 8
CENTRES = [62.5 * 2 ** k for k in range(NUM_BANDS)]
LOW_EDGE, HIGH_EDGE = 62.5 / np.sqrt(2), 8000 * np.sqrt(2)  # about 44 Hz and 11.3 kHz
# name: (size x, y (up), z in metres, absorption)
ROOMS = {
    'small': ((5.0, 2.7, 4.0), 0.2),
    'mid': ((10.0, 3.0, 7.0), 0.1),
    'hall': ((20.0, 4.0, 15.0), 0.2),
    'large': ((30.0, 10.0, 20.0), 0.2),
}


def box_obj(size, path):
    """scenes/shoebox.obj (10 x 3 x 7 m) scaled to `size`."""
    scale = np.array(size) / np.array([10.0, 3.0, 7.0])
    with open(os.path.join(ROOT, 'scenes', 'shoebox.obj')) as f, open(path, 'w') as out:
        for line in f:
            if line.startswith('v '):
                v = np.array([float(x) for x in line.split()[1:4]]) * scale
                line = 'v %g %g %g\n' % tuple(v)
            out.write(line)


def positions(size):
    lx, ly, lz = size
    return (0.27 * lx, min(1.6, 0.6 * ly), 0.52 * lz), (0.71 * lx, min(1.5, 0.55 * ly), 0.41 * lz)


def scene_json(obj, size, alpha, scattering, ir_length, where=None):
    source, listener = where or positions(size)
    material = {'absorption': [alpha] * NUM_BANDS, 'scattering': scattering}
    return {
        'mesh': obj,
        'materials': {'walls': material, 'floor': material, 'ceiling': material},
        'sources': [{'name': 'source', 'position': list(source),
                     'signal': os.path.join(ROOT, 'scenes', 'signals', 'speech.wav')}],
        'listener': {'position': list(listener), 'radius': 0.5},
        'propagation': {'max_order': 1000, 'patch_size': 0.5, 'cache_tau': 2.0,
                        'frame_rate': 15, 'ir_length': ir_length, 'air_absorption': False,
                        'speed_of_sound': C, 'exact_order': 3},
        'audio': {'sample_rate': 48000, 'block_size': 512},
    }


def read_wav(path):
    """(sample rate, float64 array [frames, channels]) of a PCM-float or PCM-16/32 WAV."""
    data = open(path, 'rb').read()
    pos, fmt, samples = 12, None, None
    while pos + 8 <= len(data):
        cid, size = data[pos:pos + 4], int.from_bytes(data[pos + 4:pos + 8], 'little')
        body = data[pos + 8:pos + 8 + size]
        if cid == b'fmt ':
            tag, channels, rate = (int.from_bytes(body[0:2], 'little'),
                                   int.from_bytes(body[2:4], 'little'),
                                   int.from_bytes(body[4:8], 'little'))
            bits = int.from_bytes(body[14:16], 'little')
            if tag == 0xFFFE:
                tag = int.from_bytes(body[24:26], 'little')
            fmt = (tag, channels, rate, bits)
        elif cid == b'data':
            samples = body
        pos += 8 + size + (size & 1)
    tag, channels, rate, bits = fmt
    dtype = {(3, 32): '<f4', (3, 64): '<f8', (1, 16): '<i2', (1, 32): '<i4'}[(tag, bits)]
    x = np.frombuffer(samples, dtype=dtype).astype(np.float64)
    if tag == 1:
        x /= float(2 ** (bits - 1))
    return rate, x.reshape(-1, channels)


def read_er(path):
    """(direct delay s, direct band energies, bin width s, bins [n, 8]) of an --er-out CSV."""
    direct_t, direct_e, times, bins = None, None, [], []
    for line in open(path):
        if line.startswith('#') or line.startswith('source'):
            continue
        f = line.strip().split(',')
        values = [float(v) for v in f[3:3 + NUM_BANDS]]
        if f[1] == 'direct':
            direct_t, direct_e = float(f[2]), np.array(values)
        elif f[1] == 'bin':
            times.append(float(f[2]))
            bins.append(values)
    return direct_t, direct_e, times[1] - times[0], np.array(bins)


def decay_parameters(energy, dt, onset):
    """G (dB re 1/(4 pi 10^2)), T30, EDT (s) and C80 (dB) of an energy sequence (per sample or
    per bin of width dt), from index `onset` on: Schroeder backward integration and least-
    squares lines over -5..-35 dB (T30) and 0..-10 dB (EDT), ISO 3382-1."""
    e = np.asarray(energy[onset:], float)
    total = e.sum()
    edc = np.cumsum(e[::-1])[::-1]
    edc_db = 10 * np.log10(np.maximum(edc / total, 1e-300))
    t = np.arange(len(e)) * dt

    def slope_time(hi, lo):
        sel = (edc_db <= hi) & (edc_db >= lo)
        if sel.sum() < 3 or edc_db[-1] > lo:
            return float('nan')
        slope = np.polyfit(t[sel], edc_db[sel], 1)[0]
        return -60.0 / slope

    k80 = int(round(0.080 / dt))
    return {'g': 10 * np.log10(total * 4 * np.pi * 100), 't30': slope_time(-5, -35),
            'edt': slope_time(0, -10),
            'c80': 10 * np.log10(e[:k80].sum() / max(e[k80:].sum(), 1e-300))}


def band_energies(segment, rate):
    """Energy of a signal segment per octave band (FFT bins between fc/sqrt 2 and fc sqrt 2)
    plus below 44 Hz and above 11.3 kHz: ([8 bands], low, high), summing to the segment's
    energy (Parseval)."""
    n = len(segment)
    spec = np.abs(np.fft.rfft(segment)) ** 2
    weight = np.full(len(spec), 2.0)
    weight[0] = 1.0
    if n % 2 == 0:
        weight[-1] = 1.0
    power = spec * weight / n
    f = np.fft.rfftfreq(n, 1.0 / rate)
    bands = [power[(f >= fc / np.sqrt(2)) & (f < fc * np.sqrt(2))].sum() for fc in CENTRES]
    return np.array(bands), power[f < LOW_EDGE].sum(), power[f >= HIGH_EDGE].sum()


def render(build, folder, tag, scene, rays, seed, duration):
    path = os.path.join(folder, tag + '.json')
    with open(path, 'w') as f:
        json.dump(scene, f)
    wav, ir, er = (os.path.join(folder, tag + x) for x in ('.wav', '-ir.wav', '-er.csv'))
    subprocess.run([os.path.join(build, 'apps', 'dpc-demo'), path, '--offline', wav,
                    '--duration', str(duration), '--rays', str(rays), '--seed', str(seed),
                    '--ir-out', ir, '--er-out', er, '--quiet'], check=True,
                   capture_output=True, text=True)
    rate, x = read_wav(ir)
    return rate, x[:, 0], read_er(er)


def band_weights(rate):
    """Each octave band's share of a white spectrum's energy: its span in Hz over Nyquist, the
    63 Hz band reaching down to 0 Hz and the 8 kHz band up to Nyquist. A band value of the ER
    is a spectral density (docs/design.md, "IR synthesis"), so the broadband energy of an IR
    that carries the ER is sum_b E_b w_b; a flat ER of E is a Dirac of energy E."""
    edges = [0.0] + [fc * np.sqrt(2) for fc in CENTRES[:-1]] + [rate / 2.0]
    return np.diff(edges) / (rate / 2.0)


def band_levels(ir, rate, er):
    """Per octave band, the IR's energy by FFT over the octave (fc / sqrt 2 .. fc sqrt 2) divided
    by the octave's share of a white spectrum, against the ER's band total (direct sound
    included), in dB: 0 when the IR carries the ER's band value as a spectral density."""
    bands, _, _ = band_energies(ir, rate)
    _, direct_e, _, bins = er
    total = bins.sum(axis=0) + direct_e
    width = np.array([fc * np.sqrt(2) - fc / np.sqrt(2) for fc in CENTRES]) / (rate / 2.0)
    return [float(10 * np.log10(b / w / t)) for b, w, t in zip(bands, width, total)]


def er_broadband(er, rate):
    direct_t, direct_e, dt, bins = er
    w = band_weights(rate)
    energy = bins @ w
    k = int(direct_t / dt)
    energy = energy.copy()
    energy[k] += direct_e @ w
    return decay_parameters(energy, dt, k), direct_e @ w


def arrivals(ir, rate, delay, energy, order, direct_energy_ir):
    """Each image source up to order 3 against the IR. With frequency-independent absorption an
    exact path is a Dirac of amplitude sqrt(I) at the sample nearest its delay. Image sources
    within 2 samples of each other form one group: on one sample they add in pressure,
    (sum sqrt(I))^2, else in energy, sum I. Per image source: the group's IR energy over its
    samples +-1 re that expectation (dB), and where the IR's largest sample within +-1 of the
    delay lies (offset in samples). Also the samples in the first 50 ms louder than the direct
    sound's peak where no image source lies within 0.5 ms."""
    samples = np.rint(delay * rate).astype(int)
    exact = order <= 3
    direct_k = samples[order == 0][0]
    rows = []
    for t, k, o in zip(delay, samples, order):
        if o == 0 or o > 3 or k + 3 >= len(ir):
            continue
        group = exact & (np.abs(samples - k) <= 2)
        ks, amps = samples[group], np.sqrt(energy[group])
        want = amps.sum() ** 2 if ks.min() == ks.max() else (amps ** 2).sum()
        got = (ir[ks.min() - 1:ks.max() + 2] ** 2).sum()
        offset = int(np.argmax(np.abs(ir[k - 1:k + 2]))) - 1
        rows.append({'order': int(o), 'delay_ms': 1000 * t, 'offset_samples': offset,
                     'ratio_db': 10 * np.log10(max(got, 1e-30) / want)})
    half = int(round(0.0005 * rate))
    peak = np.abs(ir[max(direct_k - half, 0):direct_k + half + 1]).max()
    early = np.arange(int(0.050 * rate) + direct_k)
    loud = early[np.abs(ir[early]) > peak]
    unexplained = [int(k) for k in loud if not np.any(np.abs(delay - k / rate) <= 0.0005)]
    return rows, len(unexplained)


def case_entry(ir, rate, er, onset, k0, d_bands, d_energy):
    """One rendered case's broadband, out-of-band, per-band and causality figures."""
    ir_par = decay_parameters(ir ** 2, 1.0 / rate, max(onset, 0))
    er_par, er_direct = er_broadband(er, rate)
    tail = ir[k0 + int(0.005 * rate):]
    _, t_low, t_high = band_energies(tail, rate)
    t_energy = (tail ** 2).sum()
    pre = ir[:max(onset, 0)]
    p_bands, _, _ = band_energies(pre, rate) if len(pre) else (np.zeros(8), 0, 0)
    return {
        'ir': ir_par, 'er': er_par,
        'band_level_db': band_levels(ir[max(onset, 0):], rate, er),
        'g_re_direct_ir': 10 * np.log10((ir ** 2).sum() / d_energy),
        'g_re_direct_er': er_par['g'] - 10 * np.log10(er_direct * 4 * np.pi * 100),
        'reverb_low_share': t_low / t_energy, 'reverb_high_share': t_high / t_energy,
        'pre_onset_db': 10 * np.log10(max((pre ** 2).sum(), 1e-30) / d_energy),
        'pre_onset_band_db': [10 * np.log10(max(p, 1e-30) / max(d, 1e-30))
                              for p, d in zip(p_bands, d_bands)],
    }


def image_source_figures(ir, rate, size, alpha, ir_length, d_energy):
    """The specular case against exact image sources: their decay parameters (1 ms bins) and
    the per-arrival check (arrivals())."""
    source, listener = positions(size)
    delay, energy, order = image_sources.image_sources(size, source, listener, alpha,
                                                       C * ir_length, C)
    bins = np.zeros(int(round(ir_length / 1e-3)))
    refl = order > 0
    np.add.at(bins, np.minimum((delay[refl] / 1e-3).astype(int), len(bins) - 1), energy[refl])
    k = int(delay[order == 0][0] / 1e-3)
    bins[k] += energy[order == 0][0]
    rows, unexplained = arrivals(ir, rate, delay, energy, order, d_energy)
    return {'image_sources': decay_parameters(bins, 1e-3, k), 'arrivals_order_le3': rows,
            'unexplained_loud_samples_50ms': unexplained}


def measure(build, folder, name, rays, seed):
    size, alpha = ROOMS[name]
    obj = os.path.join(folder, name + '.obj')
    box_obj(size, obj)
    source, listener = positions(size)
    r = float(np.linalg.norm(np.array(source) - np.array(listener)))
    volume, area = np.prod(size), 2 * (size[0] * size[1] + size[1] * size[2] + size[0] * size[2])
    t60 = 0.161 * volume / (area * -np.log(1 - alpha))
    ir_length = float(min(4.0, max(1.0, 1.3 * t60)))
    rate, direct_ir, _ = render(build, folder, name + '-anechoic',
                                scene_json(obj, size, 1.0, 1.0, ir_length), 256, seed, 0.3)
    onset = int(np.floor((r / C - 0.001) * rate))
    d_bands, d_low, d_high = band_energies(direct_ir, rate)
    d_energy = (direct_ir ** 2).sum()
    result = {'size_m': size, 'absorption': alpha, 'distance_m': r, 'ir_length_s': ir_length,
              'direct': {'g_ir': 10 * np.log10(d_energy * 4 * np.pi * 100),
                         'g_theory': 10 * np.log10(100 / r ** 2),
                         'low_share': d_low / d_energy, 'high_share': d_high / d_energy}}
    for case, scattering in (('diffuse', 1.0), ('specular', 0.0)):
        rate, ir, er = render(build, folder, f'{name}-{case}',
                              scene_json(obj, size, alpha, scattering, ir_length), rays, seed, 2.0)
        entry = case_entry(ir, rate, er, onset, int(round(r / C * rate)), d_bands, d_energy)
        if case == 'specular':
            entry.update(image_source_figures(ir, rate, size, alpha, ir_length, d_energy))
        result[case] = entry
    return result


# Listener distances of the causality sweep, metres, in the large room along x.
CAUSALITY_DISTANCES = (1.0, 2.0, 5.0, 10.0, 20.0)


def causality(build, folder, rays, seed):
    """Energy earlier than r/c - 1 ms per octave band (FFT of that segment) in dB re the direct
    sound's energy in the same band (from an anechoic render at the same distance), and
    broadband as a fraction of the direct sound's energy, for sources 1-20 m from the listener
    in the large room, diffuse."""
    size, alpha = ROOMS['large']
    obj = os.path.join(folder, 'causality.obj')
    box_obj(size, obj)
    rows = []
    for r in CAUSALITY_DISTANCES:
        source = (5.0, 1.6, 10.0)
        where = (source, (source[0] + r, 1.5, source[2]))
        _, anechoic, _ = render(build, folder, f'c{r:g}-anechoic',
                                scene_json(obj, size, 1.0, 1.0, 1.0, where), 256, seed, 0.3)
        rate, ir, _ = render(build, folder, f'c{r:g}',
                             scene_json(obj, size, alpha, 1.0, 1.0, where), rays, seed, 1.0)
        onset = int(np.floor((r / C - 0.001) * rate))
        d_bands, _, _ = band_energies(anechoic, rate)
        pre = ir[:max(onset, 0)]
        p_bands, _, _ = band_energies(pre, rate) if len(pre) else (np.zeros(8), 0, 0)
        rows.append({'distance_m': r,
                     'broadband_fraction': float((pre ** 2).sum() / (anechoic ** 2).sum()),
                     'band_db': [float(10 * np.log10(max(p, 1e-30) / max(d, 1e-30)))
                                 for p, d in zip(p_bands, d_bands)]})
    return rows


def failures(results, sweep):
    """The issue's criteria that a result misses, one line each (empty: all met). Broadband G
    within 0.5 dB of the ER's and, specular, of the image sources'; T30 5 %, EDT 10 %, C80 1 dB;
    out-of-band shares within 2 percentage points of the direct sound's; every image source up
    to order 3 on its sample +-1 within 0.5 dB, nothing loud unexplained in 50 ms; energy
    before r/c - 1 ms at most -30 dB re the direct sound per band from 125 Hz (63 Hz -20 dB)
    and 1 % broadband."""
    out = []
    for name, res in results.items():
        d = res['direct']
        for case in ('diffuse', 'specular'):
            e = res[case]
            refs = [('ER', e['er'])] + ([('image sources', e['image_sources'])]
                                        if case == 'specular' else [])
            for ref_name, ref in refs:
                for key, bad in (('g', abs(e['ir']['g'] - ref['g']) > 0.5),
                                 ('t30', abs(e['ir']['t30'] / ref['t30'] - 1) > 0.05),
                                 ('edt', abs(e['ir']['edt'] / ref['edt'] - 1) > 0.10),
                                 ('c80', abs(e['ir']['c80'] - ref['c80']) > 1.0)):
                    if bad:
                        out.append(f'{name} {case}: {key} of the IR against the {ref_name}')
            for share, direct in (('reverb_low_share', 'low_share'),
                                  ('reverb_high_share', 'high_share')):
                if abs(e[share] - d[direct]) > 0.02:
                    out.append(f'{name} {case}: {share} {e[share]:.3f} vs the direct sound\'s '
                               f'{d[direct]:.3f}')
        for a in res['specular']['arrivals_order_le3']:
            if abs(a['ratio_db']) > 0.5:
                out.append(f"{name}: image source at {a['delay_ms']:.3f} ms off by "
                           f"{a['ratio_db']:+.2f} dB")
        if res['specular']['unexplained_loud_samples_50ms']:
            out.append(f'{name}: loud samples in 50 ms where no image source lies')
    for row in sweep:
        if row['broadband_fraction'] > 0.01:
            out.append(f"{row['distance_m']:g} m: {100 * row['broadband_fraction']:.2f} % "
                       f"of the direct sound's energy before r/c - 1 ms")
        for b, v in enumerate(row['band_db']):
            if v > (-20 if b == 0 else -30):
                out.append(f"{row['distance_m']:g} m: {CENTRES[b]:g} Hz before r/c - 1 ms "
                           f"{v:.1f} dB re the direct sound")
    return out


def plot_specular(build, folder, path, rays, seed):
    """The small specular room's IR (first 60 ms) against its image sources up to order 3."""
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    size, alpha = ROOMS['small']
    obj = os.path.join(folder, 'plot.obj')
    box_obj(size, obj)
    rate, ir, _ = render(build, folder, 'plot', scene_json(obj, size, alpha, 0.0, 1.0), rays,
                         seed, 2.0)
    source, listener = positions(size)
    delay, energy, order = image_sources.image_sources(size, source, listener, alpha,
                                                       C * 0.06, C)
    t = np.arange(len(ir)) / rate * 1000
    end = int(0.06 * rate)
    fig, ax = plt.subplots(figsize=(9, 3.6))
    ax.plot(t[:end], ir[:end] * np.sqrt(4 * np.pi), lw=0.6, color='0.35',
            label='dpc IR (x sqrt(4 pi): 1/r for the direct sound)')
    for o, colour in ((0, 'k'), (1, 'tab:red'), (2, 'tab:orange'), (3, 'tab:green')):
        sel = order == o
        ax.plot(delay[sel] * 1000, np.sqrt(energy[sel] * 4 * np.pi), 'o', mfc='none',
                color=colour, ms=6, label=f'image sources, order {o}')
    ax.set_xlabel('time (ms)')
    ax.set_ylabel('pressure re 1 m')
    ax.set_title(f'Specular {size[0]:g} x {size[1]:g} x {size[2]:g} m room, absorption {alpha:g}:'
                 ' exact paths up to order 3, stochastic part after')
    ax.legend(fontsize=7, loc='upper right')
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def markdown(results):
    lines = ['| room | case | G IR − ER (dB) | G re direct IR − ER (dB) | T30 IR/ER | EDT IR/ER | '
             'C80 IR − ER (dB) | reverb <44 Hz / >11.3 kHz (direct) | before r/c−1 ms (dB re '
             'direct) |', '|---|---|---|---|---|---|---|---|---|']
    for name, res in results.items():
        d = res['direct']
        for case in ('diffuse', 'specular'):
            e = res[case]
            ir, er = e['ir'], e['er']
            lines.append(
                f"| {name} {'×'.join(f'{s:g}' for s in res['size_m'])} m, α {res['absorption']:g}"
                f" | {case} | {ir['g'] - er['g']:+.2f} | "
                f"{e['g_re_direct_ir'] - e['g_re_direct_er']:+.2f} | {ir['t30'] / er['t30']:.3f} | "
                f"{ir['edt'] / er['edt']:.3f} | {ir['c80'] - er['c80']:+.2f} | "
                f"{100 * e['reverb_low_share']:.1f} % / {100 * e['reverb_high_share']:.1f} % "
                f"({100 * d['low_share']:.1f} / {100 * d['high_share']:.1f}) | "
                f"{e['pre_onset_db']:.1f} |")
    return '\n'.join(lines)


def causality_markdown(sweep):
    lines = ['| distance | before r/c−1 ms, broadband (% of direct) | per band 63 Hz … 8 kHz (dB re '
             'direct) |', '|---|---|---|']
    for row in sweep:
        lines.append(f"| {row['distance_m']:g} m | {100 * row['broadband_fraction']:.2g} % | "
                     f"{', '.join(f'{v:.0f}' for v in row['band_db'])} |")
    return '\n'.join(lines)


def print_summary(results):
    """One line per room: direct sound, arrivals, per-band levels, causality per band."""
    for name, res in results.items():
        arr = res['specular']['arrivals_order_le3']
        worst = max(arr, key=lambda a: abs(a['ratio_db'])) if arr else None
        print(f"{name}: direct G {res['direct']['g_ir']:.2f} dB (theory "
              f"{res['direct']['g_theory']:.2f}); specular arrivals up to order 3: "
              f"{len(arr)}, |error| median "
              f"{np.median([abs(a['ratio_db']) for a in arr]):.1f} dB, worst "
              f"{worst['ratio_db']:+.1f} dB at {worst['delay_ms']:.2f} ms; unexplained loud "
              f"samples in 50 ms: {res['specular']['unexplained_loud_samples_50ms']}; "
              f"IR - ER per band (dB; diffuse / specular): "
              f"{', '.join(f'{v:+.2f}' for v in res['diffuse']['band_level_db'])} / "
              f"{', '.join(f'{v:+.2f}' for v in res['specular']['band_level_db'])}; "
              f"pre-onset per band (dB re direct): "
              f"{', '.join(f'{v:.0f}' for v in res['diffuse']['pre_onset_band_db'])}")




def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--build', default=os.path.join(ROOT, 'build'))
    parser.add_argument('--rooms', nargs='+', default=list(ROOMS), choices=list(ROOMS))
    parser.add_argument('--rays', type=int, default=8192)
    parser.add_argument('--seed', type=int, default=1)
    parser.add_argument('--json', help='write the results here')
    parser.add_argument('--plot', help='draw the specular IR against its image sources (PNG)')
    parser.add_argument('--check', action='store_true',
                        help='exit 1 when a criterion is missed (see failures())')
    args = parser.parse_args()
    results = {}
    with tempfile.TemporaryDirectory() as folder:
        for name in args.rooms:
            print(f'validate_ir: {name}', file=sys.stderr)
            results[name] = measure(args.build, folder, name, args.rays, args.seed)
        print('validate_ir: causality sweep', file=sys.stderr)
        sweep = causality(args.build, folder, args.rays, args.seed)
        if args.plot:
            plot_specular(args.build, folder, args.plot, args.rays, args.seed)
    if args.json:
        with open(args.json, 'w') as f:
            json.dump({'rooms': results, 'causality': sweep}, f, indent=1, default=float)
    print(markdown(results))
    print(causality_markdown(sweep))
    print_summary(results)
    missed = failures(results, sweep)
    for line in missed:
        print(f'validate_ir: missed: {line}', file=sys.stderr)
    if args.check and missed:
        sys.exit(1)


if __name__ == '__main__':
    main()
