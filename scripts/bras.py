#!/usr/bin/python3
"""BRAS's measured rooms in dpc: the synthesised IR and the energy response against measurement.

The Benchmark for Room Acoustical Simulation (BRAS; L. Aspöck, F. Brinkmann, D. Ackermann,
S. Weinzierl, M. Vorländer, "A benchmark for room acoustical simulation. Concept and database",
Applied Acoustics 2020; data DOI 10.14279/depositonce-6726.3, CC BY-SA 4.0) gives each room's
surface materials (absorption and scattering in third octaves), its source and receiver
positions, and EDT, T20, C80 and D50 measured with a dodecahedron loudspeaker. The committed
files in scenes/bras-cr2/ and scenes/bras-cr4/ hold those (see their README.md). The geometry
is not shipped: it is the RAVEN AC3D models `RavenModels/scene9.ac` (CR2) and `scene11.ac`
(CR4) of "Input and output data for informed room acoustic simulations of the BRAS scene
database" (L. Aspöck, RWTH Aachen 2020, https://publications.rwth-aachen.de/record/803828),
whose licence (CC BY-NC-SA 4.0) is not ours; download them and pass their folder with
--raven-models. The same two files are in the public repository of a peer simulator
(github.com/krzysztofarendt/building3d-rs, validation/bras/informed_sim/RavenModels/; the
copies docs/validation.md's tables were made from have the sha256 it gives). CR3 (the Konzerthaus chamber music hall, scene 10) has no AC3D model in that
record's stored copies, so it is not compared (docs/validation.md says what was searched).

Steps per room:
  convert  AC3D -> OBJ with assimp (`apt-get install assimp-utils`; AC3D polygons, some
           concave, triangulated by assimp), material names `mat_sceneNN_X` -> `X`.
           Checks: volume (divergence theorem, against BRAS's documented volume), surface
           area per material, and the clearance below each receiver (vertical ray).
  scenes   one dpc scene per variant with both sources and all five receivers (one run traces
           every pair): octave-band coefficients are the mean of the three third octaves in
           each octave (63 Hz: 50/63/80 Hz ... 8 kHz: 6.3/8/10 kHz).
             fitted         BRAS's fitted absorption and its scattering, per band
             fitted-diffuse the same absorption, scattering 1 on every surface (CR4)
             initial        BRAS's initial estimates (CR4: CR2 has no initial file here)
  render   dpc-demo --offline --ir-out --er-out per variant and seed; per pair dpc-analyze of
           the IR (what a user reads: the synthesised IR through the ISO octave filters), of the
           energy response (dpc-analyze ER.csv) and of an exact IR of it
           (dpc-analyze --as-measured).
  compare  per octave band 125 Hz - 4 kHz, the mean over the 10 pairs against BRAS's measured
           mean (octave value = mean of its three third-octave values, as BRAS gives third
           octaves only), in just noticeable differences (ISO 3382-1 annex A: EDT and T20
           5 %, C80 1 dB, D50 0.05); per metric the mean |error| over those six octaves for the
           IR, the energy response, its as-measured reading, and a peer simulator's where one
           is published (scenes/bras-ROOM/peer.csv). Sabine's and Eyring's T60 from the same
           absorption, the model's volume and areas, and dpc's air attenuation
           (dpc-analyze --air-attenuation), for the diffuse-field reading.

Writes docs/data/bras-ROOM.json, prints the tables (markdown) and, with --update-doc, puts them
into docs/validation.md between its `<!-- bras-tables -->` markers; --plot draws
docs/images/validation-bras-ROOM.png from the JSON.
Usage: /usr/bin/python3 scripts/bras.py --raven-models PATH/RavenModels [--rooms CR2 CR4]
           [--build build] [--rays 40000] [--seeds 2] [--variants fitted ...] [--wave HZ]
           [--update-doc]
       /usr/bin/python3 scripts/bras.py --plot [--rooms CR2 CR4]
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
BANDS = [63, 125, 250, 500, 1000, 2000, 4000, 8000]
COMPARED = BANDS[1:7]  # BRAS's measured third octaves start at 80 Hz; the table stops at 4 kHz
METRICS = ('edt', 't20', 'c80', 'd50')
# ISO 3382-1:2009 annex A, table A.1: just noticeable differences.
JND = {'edt': ('relative', 0.05), 't20': ('relative', 0.05), 'c80': ('absolute', 1.0),
       'd50': ('absolute', 0.05)}
# What each analysis of a render is called in the tables.
READINGS = {'ir': 'synthesised IR', 'er': 'energy response',
            'er_as_measured': 'energy response as measured'}


def bras_to_dpc(p):
    """BRAS's coordinates (x from the stage to the back, y across, z up) to RAVEN's model
    frame, which dpc reads as it is (y up, z = -y_BRAS)."""
    x, y, z = p
    return [x, z, -y]


# Per room: BRAS's name and scene number, the AC3D file, the documented volume (m^3), the
# measurement's air (deg C, % RH), sources and receivers in dpc's (= RAVEN's) frame, the
# listener sphere, the rendered duration and IR length (s).
ROOMS = {
    # CR2, the small seminar room of RWTH Aachen. Positions from RAVEN's input file
    # Scene09_Informed.rpf of the informed-simulation record (RAVEN's frame): the
    # dodecahedron's middle driver LS01-mid, LS02-mid; receivers MP01..MP05 1.23 m high.
    'CR2': {'scene': 'scene 9, the small seminar room of RWTH Aachen', 'model': 'scene9.ac',
            'prefix': 'mat_scene09_', 'volume': 145.0, 'air': (19.5, 41.7),
            'sources': {'LS1': [0.931, 0.723, 2.547], 'LS2': [0.119, 0.723, -2.880]},
            'receivers': {'MP1': [-0.993, 1.23, -1.426], 'MP2': [0.439, 1.23, 0.147],
                          'MP3': [1.361, 1.23, 0.603], 'MP4': [-1.110, 1.23, 0.256],
                          'MP5': [-0.998, 1.23, 1.409]},
            'radius': 0.3, 'duration': 2.5, 'ir_length': 3.0,
            'variants': ('fitted',)},
    # CR4, the TU Berlin auditorium: positions in BRAS's frame read from its
    # CR4_RIR_Dodecahedron.png and model (scenes/bras-cr4/README.md): the dodecahedron's
    # middle driver (1.38 m; its drivers sit at 1.117, 1.38 and 1.68 m, crossovers 177 Hz and
    # 1.42 kHz), receivers 1.23 m above the raked floor.
    'CR4': {'scene': 'scene 11, the TU Berlin auditorium', 'model': 'scene11.ac',
            'prefix': 'mat_scene11_', 'volume': 8650.0, 'air': (20.9, 37.5),
            'sources': {k: bras_to_dpc(p) for k, p in
                        {'LS1': (0.0, 4.5, 1.38), 'LS2': (-2.8, -4.5, 1.38)}.items()},
            'receivers': {k: bras_to_dpc(p) for k, p in
                          {'MP1': (8.5, 0.0, 1.09), 'MP2': (3.33, -7.95, 0.57),
                           'MP3': (9.33, -6.96, 1.18), 'MP4': (5.91, 6.34, 0.83),
                           'MP5': (11.83, 8.43, 1.43)}.items()},
            'radius': 0.5, 'duration': 2.5, 'ir_length': 3.5,
            'variants': ('fitted', 'fitted-diffuse', 'initial')},
}


def data_dir(room):
    return os.path.join(ROOT, 'scenes', 'bras-' + room.lower())


def third_octaves(path):
    """Rows of a BRAS-derived CSV (comment line, header): header fields, rows of fields."""
    with open(path) as f:
        lines = [l.strip() for l in f if l.strip() and not l.startswith('#')]
    return lines[0].split(','), [l.split(',') for l in lines[1:]]


def load_materials(room):
    header, rows = third_octaves(os.path.join(data_dir(room), 'materials.csv'))
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


def load_measured(room):
    header, rows = third_octaves(os.path.join(data_dir(room), 'measured.csv'))
    freqs = [float(x) for x in header[1:]]
    freqs = [160.0 if f == 155 else 6300.0 if f == 6350 else f for f in freqs]
    out = {}
    for r in rows:
        v = [float(x) for x in r[1:]]
        if r[0] == 'D50':
            v = [x / 100 for x in v]
        per_band = {}
        for centre in COMPARED + [8000]:
            k = int(np.argmin([abs(math.log2(f / centre)) for f in freqs]))
            per_band[centre] = float(np.mean(v[k - 1:k + 2]))
        out[r[0].lower()] = per_band
    return out


def load_peer(room):
    """A peer simulator's published octave values (scenes/bras-ROOM/peer.csv), or None."""
    path = os.path.join(data_dir(room), 'peer.csv')
    if not os.path.isfile(path):
        return None
    header, rows = third_octaves(path)
    bands = [int(x) for x in header[1:]]
    out = {}
    for r in rows:
        v = [float(x) for x in r[1:]]
        out[r[0].lower()] = {b: (x / 100 if r[0] == 'D50' else x) for b, x in zip(bands, v)}
    with open(path) as f:
        out['source'] = f.readline().lstrip('# ').strip()
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


def convert(ac, folder, room):
    """AC3D -> folder/ROOM.obj with BRAS material names; returns (vertices, faces, materials)."""
    if not shutil.which('assimp'):
        sys.exit('bras.py: assimp not found (apt-get install assimp-utils)')
    raw = os.path.join(folder, 'raw.obj')
    subprocess.run(['assimp', 'export', ac, raw, '-tri'], check=True, capture_output=True)
    out = os.path.join(folder, room.lower() + '.obj')
    prefix = ROOMS[room]['prefix']
    with open(raw) as src, open(out, 'w') as dst:
        dst.write(f'# BRAS {room} geometry, converted from RAVEN {ROOMS[room]["model"]} by '
                  'scripts/bras.py; not for redistribution (CC BY-NC-SA 4.0)\n')
        for line in src:
            if line.startswith('mtllib'):
                continue
            if line.startswith('usemtl'):
                line = 'usemtl ' + line.split()[1].replace(prefix, '') + '\n'
            dst.write(line)
    return read_obj(out)


def mesh_checks(v, f, mats):
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
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


def air_attenuation(build, air):
    """dpc's ISO 9613-1 energy attenuation m (1/m) per band at the given air (deg C, % RH)."""
    out = subprocess.run([os.path.join(build, 'apps', 'dpc-analyze'), '--air-attenuation',
                          str(air[0]), str(air[1]), '--json'],
                         check=True, capture_output=True, text=True)
    return json.loads(out.stdout)['energyAttenuationPerMetre']


def diffuse_field_t60(volume, areas, absorption, air_m, temperature):
    """Sabine and Eyring T60 per band with air (Kuttruff, Room Acoustics, eqs. 5.21, 5.24):
    24 ln10 V / (c (A + 4 m V)), A = sum S_i a_i (Sabine) or -S ln(1 - a_mean) (Eyring)."""
    c = 331.3 * math.sqrt(1 + temperature / 273.15)
    total = sum(areas.values())
    out = {'sabine': [], 'eyring': []}
    for b in range(len(BANDS)):
        a_sum = sum(areas[m] * absorption[m][b] for m in areas)
        for name, a in (('sabine', a_sum), ('eyring', -total * math.log(1 - a_sum / total))):
            out[name].append(24 * math.log(10) * volume / (c * (a + 4 * air_m[b] * volume)))
    return out


def scene(room, variant, freqs, materials, wave=0.0):
    r = ROOMS[room]
    estimate = 'initial' if variant == 'initial' else 'fitted'
    mats = {}
    for name, q in materials[estimate].items():
        absorption = octave_means(freqs, q['absorption'])
        scattering = [1.0] * 8 if variant == 'fitted-diffuse' else \
            octave_means(freqs, q['scattering'])
        mats[name] = {'source': f'BRAS {room} {estimate} estimate, octave means of third octaves',
                      'absorption': [round(x, 4) for x in absorption],
                      'scattering': [round(x, 4) for x in scattering]}
    signal = os.path.join(ROOT, 'scenes', 'signals', 'speech.wav')
    return {
        'mesh': room.lower() + '.obj',
        'materials': mats,
        'sources': [{'name': n, 'position': p, 'signal': signal} for n, p in r['sources'].items()],
        'listeners': [{'name': n, 'position': p, 'radius': r['radius']}
                      for n, p in r['receivers'].items()],
        'propagation': {'max_order': 1000, 'cache_tau': 2.0, 'frame_rate': 15,
                        'ir_length': r['ir_length'], 'temperature': r['air'][0],
                        'humidity': r['air'][1]},
        'audio': {'sample_rate': 48000, 'block_size': 512},
        **({'wave': {'enabled': True, 'max_frequency': wave}} if wave else {}),
    }


def analyze(build, path, as_measured=False):
    out = subprocess.run([os.path.join(build, 'apps', 'dpc-analyze'), path, '--json'] +
                         (['--as-measured'] if as_measured else []),
                         check=True, capture_output=True, text=True)
    j = json.loads(out.stdout)
    return j['channels'] if 'channels' in j else j['sources']


def parameters(bands):
    return {p: [b[p] if isinstance(b[p], (int, float)) else None for b in bands]
            for p in ('edt', 't20', 't30', 'c80', 'd50', 'g')}


def render(build, folder, room, variant, sc, rays, seed, threads):
    """Per source-receiver pair: the IR's, the energy response's and its as-measured
    parameters per band."""
    path = os.path.join(folder, f'{variant}.json')
    with open(path, 'w') as f:
        json.dump(sc, f, indent=1)
    tag = os.path.join(folder, f'{variant}-{seed}')
    print(f'bras: {room} {variant}, seed {seed}, {rays} rays per source per frame',
          file=sys.stderr, flush=True)
    run = subprocess.run([os.path.join(build, 'apps', 'dpc-demo'), path, '--offline',
                          tag + '.wav', '--duration', str(ROOMS[room]['duration']),
                          '--rays', str(rays), '--seed', str(seed), '--threads', str(threads),
                          '--ir-out', tag + '-ir.wav', '--er-out', tag + '.csv', '--quiet'],
                         capture_output=True, text=True)
    if run.returncode != 0:
        sys.exit(f'bras.py: dpc-demo failed on {room} {variant}: {run.stderr.strip()}')
    pairs = {}
    for listener in ROOMS[room]['receivers']:
        readings = {'ir': analyze(build, f'{tag}-ir-{listener}.wav'),
                    'er': analyze(build, f'{tag}-{listener}.csv'),
                    'er_as_measured': analyze(build, f'{tag}-{listener}.csv', True)}
        for s_index, s_name in enumerate(ROOMS[room]['sources']):
            pairs[f'{s_name}-{listener}'] = {k: parameters(v[s_index]['bands'])
                                             for k, v in readings.items()}
    return pairs


def in_jnd(parameter, sim, meas):
    kind, jnd = JND[parameter]
    return (sim / meas - 1) / jnd if kind == 'relative' else (sim - meas) / jnd


def mean_over_runs(runs):
    """Per pair, reading and parameter: the mean over the seeds per band (None if any is)."""
    out = {}
    for key, first in runs[0].items():
        out[key] = {}
        for reading, params in first.items():
            out[key][reading] = {}
            for p in params:
                vals = [[r[key][reading][p][b] for r in runs] for b in range(len(BANDS))]
                out[key][reading][p] = [float(np.mean(x)) if None not in x else None
                                        for x in vals]
    return out


def summarise(runs, measured):
    """Per reading, metric and compared band: the mean over the pairs, its spread over pairs
    and seeds, the measured value and the error in JND; and per reading and metric the mean
    |error| over the compared bands."""
    pairs = mean_over_runs(runs)
    summary, mean_abs = {}, {}
    for reading in READINGS:
        summary[reading], mean_abs[reading] = {}, {}
        for p in METRICS:
            summary[reading][p] = {}
            for b, centre in enumerate(BANDS):
                vals = [pairs[k][reading][p][b] for k in pairs]
                if None in vals or centre not in measured[p]:
                    continue
                seed_means = [float(np.mean([r[k][reading][p][b] for k in r])) for r in runs
                              if None not in [r[k][reading][p][b] for k in r]]
                entry = {'mean': float(np.mean(vals)), 'pair_sd': float(np.std(vals, ddof=1)),
                         'seed_sd': float(np.std(seed_means, ddof=1))
                         if len(seed_means) > 1 else None,
                         'measured': measured[p][centre]}
                entry['jnd'] = in_jnd(p, entry['mean'], entry['measured'])
                summary[reading][p][str(centre)] = entry
            errs = [abs(summary[reading][p][str(c)]['jnd']) for c in COMPARED
                    if str(c) in summary[reading][p]]
            mean_abs[reading][p] = float(np.mean(errs)) if len(errs) == len(COMPARED) else None
    return pairs, summary, mean_abs


def peer_errors(peer, measured):
    """Mean |error| in JND over the compared bands of the peer's values, per metric."""
    if not peer:
        return None
    out = {}
    for p in METRICS:
        errs = [abs(in_jnd(p, peer[p][c], measured[p][c])) for c in COMPARED if c in peer.get(p, {})]
        out[p] = float(np.mean(errs)) if len(errs) == len(COMPARED) else None
    return out


def run_room(args, room, folder):
    freqs, materials = load_materials(room)
    measured = load_measured(room)
    ac = os.path.join(args.raven_models, ROOMS[room]['model'])
    if not os.path.isfile(ac):
        sys.exit(f'bras.py: --raven-models: {ac}: no such file')
    result = {'room': room, 'scene': ROOMS[room]['scene'],
              'measured': {p: {str(b): v for b, v in d.items()} for p, d in measured.items()},
              'variants': {}, 'rays': args.rays, 'seeds': args.seeds}
    v, f, mats = convert(ac, folder, room)
    volume, areas = mesh_checks(v, f, mats)
    result['model'] = {'triangles': int(len(f)), 'volume_m3': volume,
                       'volume_documented_m3': ROOMS[room]['volume'],
                       'area_m2': {m: round(a, 1) for m, a in sorted(areas.items())}}
    print(f'bras: {room}: {len(f)} triangles, volume {volume:.0f} m^3 (BRAS documents '
          f'{ROOMS[room]["volume"]:.0f}), area {sum(areas.values()):.0f} m^2', file=sys.stderr)
    clear = {}
    for name, p in {**ROOMS[room]['sources'], **ROOMS[room]['receivers']}.items():
        clear[name] = clearance_below(v, f, p)
        if not clear[name] < 20:
            sys.exit(f'bras.py: {room} {name} at {p} has no floor below it: the model and the '
                     'positions disagree')
    result['clearance_below_m'] = clear
    air_m = air_attenuation(args.build, ROOMS[room]['air'])
    variants = [x for x in args.variants if x in ROOMS[room]['variants']]
    for variant in variants:
        sc = scene(room, variant, freqs, materials, args.wave)
        absorption = {m: d['absorption'] for m, d in sc['materials'].items()}
        runs = [render(args.build, folder, room, variant, sc, args.rays, seed, args.threads)
                for seed in range(1, args.seeds + 1)]
        pairs, summary, mean_abs = summarise(runs, measured)
        result['variants'][variant] = {
            'pairs': pairs, 'summary': summary, 'mean_abs_jnd': mean_abs,
            'diffuse_field_t60': {k: dict(zip(map(str, BANDS), x)) for k, x in
                                  diffuse_field_t60(volume, areas, absorption, air_m,
                                                    ROOMS[room]['air'][0]).items()}}
    peer = load_peer(room)
    if peer:
        result['peer'] = {'source': peer['source'], 'mean_abs_jnd': peer_errors(peer, measured),
                          'values': {p: {str(b): x for b, x in peer[p].items()} for p in METRICS}}
    return result


def cell(x, fmt='{:.2f}'):
    return '—' if x is None else fmt.format(x)


def tables(results):
    """The markdown tables: per room and metric the mean |error| (JND) of each reading and the
    IR's excess over the energy response read directly (ideal bands) and through the octave
    filters as the IR is (what the synthesis alone adds), then per room the IR's values per
    band against the measured ones."""
    lines = ['| room | metric | synthesised IR | energy response | energy response as '
             'measured | peer simulator | IR − energy response | IR − as measured |',
             '|---|---|---|---|---|---|---|---|']
    minus = lambda a, b: None if None in (a, b) else a - b
    for room, r in results.items():
        d = r['variants'].get('fitted')
        if not d:
            continue
        peer = r.get('peer', {}).get('mean_abs_jnd')
        for p in METRICS:
            m = d['mean_abs_jnd']
            lines.append(f"| {room} | {p.upper()} | {cell(m['ir'][p])} | {cell(m['er'][p])} | "
                         f"{cell(m['er_as_measured'][p])} | "
                         f"{cell(peer[p] if peer else None)} | "
                         f"{cell(minus(m['ir'][p], m['er'][p]), '{:+.2f}')} | "
                         f"{cell(minus(m['ir'][p], m['er_as_measured'][p]), '{:+.2f}')} |")
    out = ['\n'.join(lines)]
    for room, r in results.items():
        d = r['variants'].get('fitted')
        if not d:
            continue
        rows = [f'{room}, synthesised IR, mean over the 10 pairs (measured), error in JND:', '',
                '| | ' + ' | '.join(str(c) for c in COMPARED) + ' |',
                '|---' * (len(COMPARED) + 1) + '|']
        for p in METRICS:
            cells = []
            for c in COMPARED:
                e = d['summary']['ir'][p].get(str(c))
                cells.append('—' if e is None else
                             f"{e['mean']:.2f} ({e['measured']:.2f}) {e['jnd']:+.1f}")
            rows.append(f'| {p.upper()} | ' + ' | '.join(cells) + ' |')
        rows.append('| Eyring T60 (s) | ' + ' | '.join(
            f"{d['diffuse_field_t60']['eyring'][str(c)]:.2f}" for c in COMPARED) + ' |')
        out.append('\n'.join(rows))
    return '\n\n'.join(out)


def update_doc(text):
    path = os.path.join(ROOT, 'docs', 'validation.md')
    with open(path) as f:
        doc = f.read()
    marker = '<!-- bras-tables -->'
    parts = doc.split(marker)
    if len(parts) != 3:
        sys.exit(f'bras.py: {path}: needs exactly two "{marker}" lines around the tables')
    with open(path, 'w') as f:
        f.write(parts[0] + marker + '\n\n' + text + '\n\n' + marker + parts[2])
    print(f'bras: updated {path}', file=sys.stderr)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--raven-models',
                    help='folder with RAVEN scene9.ac and scene11.ac (BRAS informed-simulation '
                         'record 803828, RavenModels/)')
    ap.add_argument('--rooms', nargs='+', default=list(ROOMS), choices=list(ROOMS))
    ap.add_argument('--build', default=os.path.join(ROOT, 'build'))
    ap.add_argument('--rays', type=int, default=40000)
    ap.add_argument('--seeds', type=int, default=2)
    ap.add_argument('--threads', type=int, default=0)
    ap.add_argument('--variants', nargs='+', default=['fitted'],
                    choices=['fitted', 'fitted-diffuse', 'initial'])
    ap.add_argument('--wave', type=float, default=0.0, metavar='HZ',
                    help='join the wave band up to HZ (scene key wave, docs/wave.md; crossover '
                         'at HZ / 2) to every IR; the JSON goes to bras-ROOM-waveHZ.json')
    ap.add_argument('--plot', action='store_true', help='only draw the images from the JSON')
    ap.add_argument('--data-dir', default=os.path.join(ROOT, 'docs', 'data'),
                    help='where bras-ROOM.json goes (the images are drawn only for docs/data)')
    ap.add_argument('--update-doc', action='store_true',
                    help="put the tables into docs/validation.md between its markers")
    args = ap.parse_args()
    suffix = f'-wave{args.wave:g}' if args.wave else ''
    json_path = lambda room: os.path.join(args.data_dir, f'bras-{room.lower()}{suffix}.json')
    draw = os.path.abspath(args.data_dir) == os.path.join(ROOT, 'docs', 'data') and not args.wave
    if args.plot:
        for room in args.rooms:
            with open(json_path(room)) as f:
                plot(json.load(f))
        return
    if not args.raven_models:
        sys.exit('bras.py: --raven-models: the folder of RAVEN scene9.ac / scene11.ac is '
                 'required (see --help)')
    results = {}
    for room in args.rooms:
        with tempfile.TemporaryDirectory() as folder:
            results[room] = run_room(args, room, folder)
        os.makedirs(os.path.dirname(json_path(room)), exist_ok=True)
        with open(json_path(room), 'w') as f:
            json.dump(results[room], f, indent=1)
        if draw:
            plot(results[room])
    text = tables(results)
    print(text)
    if args.update_doc:
        update_doc(text)


def plot(result):
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    room = result['room']
    fig, axes = plt.subplots(1, 4, figsize=(16, 4))
    labels = {'edt': 'EDT (s)', 't20': 'T20 (s)', 'c80': 'C80 (dB)', 'd50': 'D50'}
    x = np.arange(len(COMPARED))
    styles = {'ir': ('o-', 'C0'), 'er': ('s--', 'C1'), 'er_as_measured': ('^:', 'C2')}
    d = result['variants']['fitted']
    for ax, p in zip(axes, METRICS):
        meas = [result['measured'][p][str(c)] for c in COMPARED]
        kind, jnd = JND[p]
        lo = [m * (1 - jnd) if kind == 'relative' else m - jnd for m in meas]
        hi = [m * (1 + jnd) if kind == 'relative' else m + jnd for m in meas]
        ax.fill_between(x, lo, hi, color='0.85', label='measured ± 1 JND')
        ax.plot(x, meas, 'k-', lw=2, label='measured (BRAS)')
        for reading, (fmt, color) in styles.items():
            s = d['summary'][reading][p]
            ys = [s.get(str(c), {}).get('mean', np.nan) for c in COMPARED]
            err = [s.get(str(c), {}).get('pair_sd', np.nan) for c in COMPARED]
            ax.errorbar(x, ys, yerr=err if reading == 'ir' else None, fmt=fmt, color=color,
                        capsize=2, label=f'dpc, {READINGS[reading]}')
        if 'peer' in result:
            ax.plot(x, [result['peer']['values'][p].get(str(c), np.nan) for c in COMPARED], 'x',
                    color='C3', label='peer simulator')
        if p == 't20':
            ax.plot(x, [d['diffuse_field_t60']['eyring'][str(c)] for c in COMPARED], ':',
                    color='0.4', label='Eyring, same absorption')
        ax.set_xticks(x)
        ax.set_xticklabels([f'{c // 1000}k' if c >= 1000 else str(c) for c in COMPARED])
        ax.set_xlabel('octave band (Hz)')
        ax.set_title(labels[p])
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=7)
    axes[1].legend(fontsize=7)
    fig.suptitle(f'BRAS {room} ({result["scene"]}): dpc, mean over 10 source-receiver pairs '
                 '(bars: spread over pairs), vs measured', fontsize=10)
    fig.tight_layout()
    image = os.path.join(ROOT, 'docs', 'images', f'validation-bras-{room.lower()}.png')
    os.makedirs(os.path.dirname(image), exist_ok=True)
    fig.savefig(image, dpi=110)
    print(f'bras: wrote {image}', file=sys.stderr)


if __name__ == '__main__':
    main()
