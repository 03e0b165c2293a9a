#!/usr/bin/python3
"""BRAS scene CR4 (the TU Berlin auditorium, 8,650 m^3) in dpc, against its measurements.

The Benchmark for Room Acoustical Simulation (BRAS; L. Aspöck, F. Brinkmann, D. Ackermann,
S. Weinzierl, M. Vorländer, "A benchmark for room acoustical simulation. Concept and database",
Applied Acoustics 2020; data DOI 10.14279/depositonce-6726.3, CC BY-SA 4.0) gives the room's
surface materials (absorption and scattering in third octaves), its source and receiver
positions, and EDT, T20, C80 and D50 measured with a dodecahedron loudspeaker. The committed
files in scenes/bras-cr4/ hold those (see its README.md). The geometry is not shipped: it is
the RAVEN AC3D model `RavenModels/scene11.ac` of "Input and output data for informed room
acoustic simulations of the BRAS scene database" (L. Aspöck, RWTH Aachen 2020,
https://publications.rwth-aachen.de/record/803828), whose licence (CC BY-NC-SA 4.0) is not
ours; download it and pass it with --ac.

Steps:
  convert  AC3D -> OBJ with assimp (`apt-get install assimp-utils`; AC3D polygons, some
           concave, triangulated by assimp), material names `mat_scene11_X` -> `X`.
           Checks: volume (divergence theorem; BRAS documents 8,650 m^3), surface area per
           material, and the clearance below each receiver (vertical ray).
  scenes   one dpc scene per variant, with both sources and all five receivers (one run
           traces every pair): octave-band coefficients are the mean of the three third
           octaves in each octave (63 Hz: 50/63/80 Hz ... 8 kHz: 6.3/8/10 kHz).
             fitted         BRAS's fitted absorption and its scattering, per band
             fitted-diffuse the same absorption, scattering 1 on every surface
             initial        BRAS's initial estimates (absorption and scattering)
  render   dpc-demo --offline --er-out per variant and seed; dpc-analyze --json per pair
           (with --as-measured: dpc-analyze --as-measured, the octave filters' effect on an
           exact IR included, as in a measurement).
  compare  per octave band 125 Hz - 8 kHz, the mean over the 10 pairs against BRAS's measured
           mean (octave value = mean of its three third-octave values, as BRAS gives third
           octaves only), in just noticeable differences (ISO 3382-1 annex A: EDT and T20
           5 %, C80 1 dB, D50 0.05); and Sabine's and Eyring's T60 from the same absorption,
           the model's volume and areas, and dpc's air attenuation (dpc-analyze
           --air-attenuation), for the diffuse-field reading.

Coordinates: BRAS gives positions as (x from the stage to the back, y across, z up from the
stage floor); RAVEN's model is y up with z = -y_BRAS, so a BRAS point (x, y, z) is
(x, z, -y) here (RAVEN's CR2 input files place LS1 at z = +2.547 where BRAS has y = -2.55).

Writes docs/data/bras-cr4.json and prints the table (markdown); --plot draws
docs/images/validation-bras-cr4.png from the JSON.
Usage: /usr/bin/python3 scripts/bras_cr4.py --ac PATH/scene11.ac [--build build]
           [--rays 40000] [--seeds 2] [--variants fitted fitted-diffuse initial]
       /usr/bin/python3 scripts/bras_cr4.py --plot
"""
import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DATA = os.path.join(ROOT, 'scenes', 'bras-cr4')
BANDS = [63, 125, 250, 500, 1000, 2000, 4000, 8000]
COMPARED = BANDS[1:]  # BRAS's measured third octaves start at 80 Hz
# ISO 3382-1:2009 annex A, table A.1: just noticeable differences.
JND = {'edt': ('relative', 0.05), 't20': ('relative', 0.05), 'c80': ('absolute', 1.0),
       'd50': ('absolute', 0.05)}
# BRAS CR4 sources (dodecahedron: drivers at 1.117, 1.38 and 1.68 m above the stage, crossovers
# 177 Hz and 1.42 kHz; the middle driver's height stands for all, dpc's source is one point)
# and receivers (1.23 m above the raked floor), BRAS coordinates, metres; read from BRAS's
# CR4_RIR_Dodecahedron.png and model (scenes/bras-cr4/README.md).
SOURCES = {'LS1': (0.0, 4.5, 1.38), 'LS2': (-2.8, -4.5, 1.38)}
RECEIVERS = {'MP1': (8.5, 0.0, 1.09), 'MP2': (3.33, -7.95, 0.57), 'MP3': (9.33, -6.96, 1.18),
             'MP4': (5.91, 6.34, 0.83), 'MP5': (11.83, 8.43, 1.43)}
TEMPERATURE_C, HUMIDITY = 20.9, 37.5  # BRAS's measurement conditions for CR4
VOLUME_DOCUMENTED = 8650.0


def to_dpc(p):
    x, y, z = p
    return [x, z, -y]


def third_octaves(path):
    """Rows of a BRAS-derived CSV (comment line, header): {key: values}, frequencies."""
    with open(path) as f:
        lines = [l.strip() for l in f if l.strip() and not l.startswith('#')]
    header = lines[0].split(',')
    return header, [l.split(',') for l in lines[1:]]


def load_materials():
    header, rows = third_octaves(os.path.join(DATA, 'materials.csv'))
    freqs = [float(x) for x in header[3:]]
    out = {}
    for r in rows:
        out.setdefault(r[1], {}).setdefault(r[0], {})[r[2]] = [float(x) for x in r[3:]]
    return freqs, out


def octave_means(freqs, values):
    """Octave-band value as the mean of the three third octaves around each centre."""
    out = []
    for centre in BANDS:
        k = int(np.argmin([abs(math.log2(f / centre)) for f in freqs]))
        out.append(float(np.mean(values[k - 1:k + 2])))
    return out


def load_measured():
    header, rows = third_octaves(os.path.join(DATA, 'measured.csv'))
    freqs = [float(x) for x in header[1:]]
    freqs = [160.0 if f == 155 else 6300.0 if f == 6350 else f for f in freqs]
    out = {}
    for r in rows:
        v = [float(x) for x in r[1:]]
        if r[0] == 'D50':
            v = [x / 100 for x in v]
        per_band = {}
        for centre in COMPARED:
            k = int(np.argmin([abs(math.log2(f / centre)) for f in freqs]))
            per_band[centre] = float(np.mean(v[k - 1:k + 2]))
        out[r[0].lower()] = per_band
    return out


def read_obj(path):
    vertices, faces, mats, current = [], [], [], None
    with open(path) as f:
        for line in f:
            w = line.split()
            if not w:
                continue
            if w[0] == 'v':
                vertices.append([float(x) for x in w[1:4]])
            elif w[0] == 'usemtl':
                current = w[1]
            elif w[0] == 'f':
                idx = [int(x.split('/')[0]) - 1 for x in w[1:]]
                for i in range(1, len(idx) - 1):
                    faces.append((idx[0], idx[i], idx[i + 1]))
                    mats.append(current)
    return np.array(vertices), np.array(faces), mats


def convert(ac, folder):
    """AC3D -> folder/cr4.obj with BRAS material names; returns (vertices, faces, materials)."""
    if not shutil.which('assimp'):
        sys.exit('bras_cr4.py: assimp not found (apt-get install assimp-utils)')
    raw = os.path.join(folder, 'raw.obj')
    subprocess.run(['assimp', 'export', ac, raw, '-tri'], check=True, capture_output=True)
    out = os.path.join(folder, 'cr4.obj')
    with open(raw) as src, open(out, 'w') as dst:
        dst.write('# BRAS CR4 (scene 11) geometry, converted from RAVEN scene11.ac by '
                  'scripts/bras_cr4.py; not for redistribution (CC BY-NC-SA 4.0)\n')
        for line in src:
            if line.startswith('mtllib'):
                continue
            if line.startswith('usemtl'):
                line = 'usemtl ' + line.split()[1].replace('mat_scene11_', '') + '\n'
            dst.write(line)
    return read_obj(out)


def mesh_checks(v, f, mats):
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    cross = np.cross(b - a, c - a)
    area = 0.5 * np.linalg.norm(cross, axis=1)
    volume = abs(float(np.sum(np.einsum('ij,ij->i', a, np.cross(b, c))) / 6.0))
    areas = {}
    for m, s in zip(mats, area):
        areas[m] = areas.get(m, 0.0) + float(s)
    return volume, areas


def clearance_below(v, f, point):
    """Distance from point straight down (-y) to the first triangle (Moller-Trumbore)."""
    o, d = np.array(point, float), np.array([0.0, -1.0, 0.0])
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    e1, e2 = b - a, c - a
    p = np.cross(d, e2)
    det = np.einsum('ij,ij->i', e1, p)
    ok = np.abs(det) > 1e-12
    inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
    t0 = o - a
    u = np.einsum('ij,ij->i', t0, p) * inv
    q = np.cross(t0, e1)
    w = (q @ d) * inv
    t = np.einsum('ij,ij->i', e2, q) * inv
    hit = ok & (u >= 0) & (w >= 0) & (u + w <= 1) & (t > 1e-6)
    return float(t[hit].min()) if hit.any() else math.inf


def air_attenuation(build):
    """dpc's ISO 9613-1 energy attenuation m (1/m) per band at BRAS's air conditions."""
    out = subprocess.run([os.path.join(build, 'apps', 'dpc-analyze'), '--air-attenuation',
                          str(TEMPERATURE_C), str(HUMIDITY), '--json'],
                         check=True, capture_output=True, text=True)
    return json.loads(out.stdout)['energyAttenuationPerMetre']


def diffuse_field_t60(volume, areas, absorption, air_m):
    """Sabine and Eyring T60 per band with air (Kuttruff, Room Acoustics, eqs. 5.21, 5.24):
    24 ln10 V / (c (A + 4 m V)), A = sum S_i a_i (Sabine) or -S ln(1 - a_mean) (Eyring)."""
    c = 331.3 * math.sqrt(1 + TEMPERATURE_C / 273.15)
    total = sum(areas.values())
    out = {'sabine': [], 'eyring': []}
    for b in range(len(BANDS)):
        a_sum = sum(areas[m] * absorption[m][b] for m in areas)
        for name, a in (('sabine', a_sum), ('eyring', -total * math.log(1 - a_sum / total))):
            out[name].append(24 * math.log(10) * volume / (c * (a + 4 * air_m[b] * volume)))
    return out


def scene(variant, freqs, materials):
    estimate = 'initial' if variant == 'initial' else 'fitted'
    mats = {}
    for name, q in materials[estimate].items():
        absorption = octave_means(freqs, q['absorption'])
        scattering = [1.0] * 8 if variant == 'fitted-diffuse' else \
            octave_means(freqs, q['scattering'])
        mats[name] = {'source': f'BRAS CR4 {estimate} estimate, octave means of third octaves',
                      'absorption': [round(x, 4) for x in absorption],
                      'scattering': [round(x, 4) for x in scattering]}
    signal = os.path.join(ROOT, 'scenes', 'signals', 'speech.wav')
    return {
        'mesh': 'cr4.obj',
        'materials': mats,
        'sources': [{'name': n, 'position': to_dpc(p), 'signal': signal}
                    for n, p in SOURCES.items()],
        'listeners': [{'name': n, 'position': to_dpc(p), 'radius': 0.5}
                      for n, p in RECEIVERS.items()],
        'propagation': {'max_order': 1000, 'cache_tau': 2.0, 'frame_rate': 15,
                        'ir_length': 3.5, 'temperature': TEMPERATURE_C, 'humidity': HUMIDITY},
        'audio': {'sample_rate': 48000, 'block_size': 512},
    }


def analyze(build, csv, as_measured):
    out = subprocess.run([os.path.join(build, 'apps', 'dpc-analyze'), csv, '--json'] +
                         (['--as-measured'] if as_measured else []),
                         check=True, capture_output=True, text=True)
    return json.loads(out.stdout)['sources']


def render(build, folder, variant, sc, rays, seed, threads, as_measured):
    path = os.path.join(folder, f'{variant}.json')
    with open(path, 'w') as f:
        json.dump(sc, f, indent=1)
    wav = os.path.join(folder, f'{variant}-{seed}.wav')
    csv = os.path.join(folder, f'{variant}-{seed}.csv')
    print(f'bras_cr4: rendering {variant}, seed {seed}, {rays} rays per source per frame',
          file=sys.stderr, flush=True)
    run = subprocess.run([os.path.join(build, 'apps', 'dpc-demo'), path, '--offline', wav,
                          '--duration', '2.5', '--rays', str(rays), '--seed', str(seed),
                          '--threads', str(threads), '--er-out', csv, '--quiet'],
                         capture_output=True, text=True)
    if run.returncode != 0:
        sys.exit(f'bras_cr4.py: dpc-demo failed on {variant}: {run.stderr.strip()}')
    pairs = {}
    for listener in RECEIVERS:
        sources = analyze(build, os.path.join(folder, f'{variant}-{seed}-{listener}.csv'),
                          as_measured)
        for s_index, s_name in enumerate(SOURCES):
            bands = sources[s_index]['bands']
            pairs[f'{s_name}-{listener}'] = {
                p: [b[p] if isinstance(b[p], (int, float)) else None for b in bands]
                for p in ('edt', 't20', 't30', 'c80', 'd50', 'g')}
    return pairs


def in_jnd(parameter, sim, meas):
    kind, jnd = JND[parameter]
    return (sim / meas - 1) / jnd if kind == 'relative' else (sim - meas) / jnd


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--ac', help='RAVEN scene11.ac (BRAS informed-simulation record 803828)')
    ap.add_argument('--build', default=os.path.join(ROOT, 'build'))
    ap.add_argument('--rays', type=int, default=40000)
    ap.add_argument('--seeds', type=int, default=2)
    ap.add_argument('--threads', type=int, default=0)
    ap.add_argument('--variants', nargs='+', default=['fitted', 'fitted-diffuse', 'initial'],
                    choices=['fitted', 'fitted-diffuse', 'initial'])
    ap.add_argument('--out', default=os.path.join(ROOT, 'docs', 'data', 'bras-cr4.json'))
    ap.add_argument('--image', default=os.path.join(ROOT, 'docs', 'images',
                                                     'validation-bras-cr4.png'))
    ap.add_argument('--plot', action='store_true', help='only draw --image from --out')
    ap.add_argument('--as-measured', action='store_true',
                    help='analyse the energy responses as the band analysis of an exact IR would '
                         'read them (dpc-analyze --as-measured: octave filters included, as in '
                         'the measured values)')
    args = ap.parse_args()
    if args.plot:
        with open(args.out) as f:
            plot(json.load(f), args.image)
        return
    if not args.ac:
        sys.exit('bras_cr4.py: --ac: the RAVEN model scene11.ac is required (see --help)')
    if not os.path.isfile(args.ac):
        sys.exit(f'bras_cr4.py: --ac: {args.ac}: no such file')
    freqs, materials = load_materials()
    measured = load_measured()
    result = {'measured': {p: {str(b): v for b, v in d.items()} for p, d in measured.items()},
              'variants': {}, 'rays': args.rays, 'seeds': args.seeds,
              'as_measured': args.as_measured}
    with tempfile.TemporaryDirectory() as folder:
        v, f, mats = convert(args.ac, folder)
        volume, areas = mesh_checks(v, f, mats)
        result['model'] = {'triangles': int(len(f)), 'volume_m3': volume,
                           'volume_documented_m3': VOLUME_DOCUMENTED,
                           'area_m2': {m: round(a, 1) for m, a in sorted(areas.items())}}
        print(f'bras_cr4: {len(f)} triangles, volume {volume:.0f} m^3 '
              f'(BRAS documents {VOLUME_DOCUMENTED:.0f}), area {sum(areas.values()):.0f} m^2',
              file=sys.stderr)
        clear = {}
        for name, p in {**SOURCES, **RECEIVERS}.items():
            clear[name] = clearance_below(v, f, to_dpc(p))
            if not clear[name] < 20:
                sys.exit(f'bras_cr4.py: {name} at {to_dpc(p)} has no floor below it: the '
                         'model and the positions disagree')
        result['clearance_below_m'] = clear
        print('bras_cr4: height above the surface below: ' +
              ', '.join(f'{k} {c:.2f} m' for k, c in clear.items()), file=sys.stderr)
        air_m = air_attenuation(args.build)
        for variant in args.variants:
            sc = scene(variant, freqs, materials)
            absorption = {m: d['absorption'] for m, d in sc['materials'].items()}
            runs = [render(args.build, folder, variant, sc, args.rays, seed, args.threads,
                           args.as_measured)
                    for seed in range(1, args.seeds + 1)]
            pairs = {}
            for key in runs[0]:
                pairs[key] = {}
                for p in runs[0][key]:
                    vals = [[r[key][p][b] for r in runs] for b in range(len(BANDS))]
                    pairs[key][p] = [float(np.mean(x)) if None not in x else None for x in vals]
            summary = {}
            for p in ('edt', 't20', 'c80', 'd50'):
                summary[p] = {}
                for b, centre in enumerate(BANDS):
                    vals = [pairs[k][p][b] for k in pairs]
                    seed_means = [float(np.mean([r[k][p][b] for k in r])) for r in runs
                                  if None not in [r[k][p][b] for k in r]]
                    if None in vals:
                        continue
                    entry = {'mean': float(np.mean(vals)), 'pair_sd': float(np.std(vals, ddof=1)),
                             'seed_sd': float(np.std(seed_means, ddof=1))
                             if len(seed_means) > 1 else None}
                    if centre in COMPARED:
                        entry['measured'] = measured[p][centre]
                        entry['jnd'] = in_jnd(p, entry['mean'], measured[p][centre])
                    summary[p][str(centre)] = entry
            result['variants'][variant] = {
                'pairs': pairs, 'summary': summary,
                'diffuse_field_t60': {k: dict(zip(map(str, BANDS), v)) for k, v in
                                      diffuse_field_t60(volume, areas, absorption, air_m).items()},
                'mean_scattering': {str(c): float(np.average(
                    [sc['materials'][m]['scattering'][b] for m in areas],
                    weights=[areas[m] for m in areas])) for b, c in enumerate(BANDS)}}
    os.makedirs(os.path.dirname(args.out), exist_ok=True)
    with open(args.out, 'w') as f:
        json.dump(result, f, indent=1)
    print_table(result)
    plot(result, args.image)


def print_table(result):
    for variant, d in result['variants'].items():
        print(f'\n{variant}: mean over the 10 pairs (measured), difference in JNDs')
        print('| | ' + ' | '.join(str(c) for c in COMPARED) + ' |')
        print('|---' * (len(COMPARED) + 1) + '|')
        for p in ('edt', 't20', 'c80', 'd50'):
            cells = []
            for c in COMPARED:
                e = d['summary'][p].get(str(c))
                cells.append('—' if e is None else
                             f"{e['mean']:.2f} ({e['measured']:.2f}) {e['jnd']:+.1f}")
            print(f'| {p.upper()} | ' + ' | '.join(cells) + ' |')
        for k in ('sabine', 'eyring'):
            print(f'| {k.capitalize()} T60 | ' + ' | '.join(
                f"{d['diffuse_field_t60'][k][str(c)]:.2f}" for c in COMPARED) + ' |')


def plot(result, image):
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 4, figsize=(16, 4))
    labels = {'edt': 'EDT (s)', 't20': 'T20 (s)', 'c80': 'C80 (dB)', 'd50': 'D50'}
    x = np.arange(len(COMPARED))
    styles = {'fitted': ('o-', 'C0'), 'fitted-diffuse': ('s--', 'C1'), 'initial': ('^:', 'C2')}
    for ax, p in zip(axes, ('edt', 't20', 'c80', 'd50')):
        meas = [result['measured'][p][str(c)] for c in COMPARED]
        kind, jnd = JND[p]
        lo = [m * (1 - jnd) if kind == 'relative' else m - jnd for m in meas]
        hi = [m * (1 + jnd) if kind == 'relative' else m + jnd for m in meas]
        ax.fill_between(x, lo, hi, color='0.85', label='measured ± 1 JND')
        ax.plot(x, meas, 'k-', lw=2, label='measured (BRAS)')
        for variant, d in result['variants'].items():
            fmt, color = styles[variant]
            ys = [d['summary'][p].get(str(c), {}).get('mean', np.nan) for c in COMPARED]
            err = [d['summary'][p].get(str(c), {}).get('pair_sd', np.nan) for c in COMPARED]
            ax.errorbar(x, ys, yerr=err, fmt=fmt, color=color, capsize=2, label=f'dpc, {variant}')
            if p == 't20' and variant != 'fitted-diffuse':  # same absorption as 'fitted'
                ax.plot(x, [d['diffuse_field_t60']['eyring'][str(c)] for c in COMPARED], ':',
                        color=color, alpha=0.7, label=f'Eyring, {variant} absorption')
        ax.set_xticks(x)
        ax.set_xticklabels([f'{c // 1000}k' if c >= 1000 else str(c) for c in COMPARED])
        ax.set_xlabel('octave band (Hz)')
        ax.set_title(labels[p])
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=7)
    axes[1].legend(fontsize=7)
    fig.suptitle('BRAS CR4 auditorium: dpc (mean over 10 source-receiver pairs, bars: spread '
                 'over pairs) vs measured', fontsize=10)
    fig.tight_layout()
    os.makedirs(os.path.dirname(image), exist_ok=True)
    fig.savefig(image, dpi=110)
    print(f'bras_cr4: wrote {image}', file=sys.stderr)


if __name__ == '__main__':
    main()
