#!/usr/bin/python3
"""Room-acoustic parameters of the diffuse path cache against plain path tracing.

The 10 x 7 x 3 m shoebox (scenes/shoebox.obj) with every surface at absorption 0.1 in every
band, once fully diffuse (scattering 1) and once specular (scattering 0); one source, one
static listener (R = 0.5 m), tau = 1 s, 15 frames/s, 3 s rendered at 20,000 rays per frame.
For each estimator and seed, dpc-demo writes the last frame's energy response (--er-out) and
dpc-analyze reports G, C80 and EDT per octave band from it (no IR synthesis in between).
Path tracing's last frame is one frame of 20,000 rays; its seed-to-seed scatter is printed
as the Monte Carlo error of the comparison.

Writes docs/data/cache-vs-path-tracing.json and prints a table. --plot JSON... draws the
differences per band of one or more such files, with the targets (G 0.3 dB, C80 0.5 dB,
EDT 5 %) and path tracing's seed-to-seed standard deviation, to --image.
Usage: /usr/bin/python3 scripts/cache_vs_path_tracing.py [--build build] [--seeds 3]
       [--rays 20000] [--cache-memory-mb 64] [--out docs/data/cache-vs-path-tracing.json]
       /usr/bin/python3 scripts/cache_vs_path_tracing.py --plot A.json [B.json ...]
       [--image docs/images/cache-vs-path-tracing.png]
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BANDS = ['63', '125', '250', '500', '1000', '2000', '4000', '8000']
PARAMS = ['g', 'c80', 'edt']


def scene(scattering):
    material = {'absorption': [0.1] * 8, 'scattering': scattering}
    return {
        'mesh': os.path.join(ROOT, 'scenes', 'shoebox.obj'),
        'materials': {'walls': material, 'floor': material, 'ceiling': material},
        'sources': [{'name': 'talker', 'position': [2.0, 1.6, 3.5],
                     'signal': os.path.join(ROOT, 'scenes', 'signals', 'speech.wav')}],
        'listener': {'position': [7.0, 1.6, 3.5], 'radius': 0.5},
        'propagation': {'max_order': 200, 'patch_size': 0.5, 'cache_tau': 1.0,
                        'frame_rate': 15, 'ir_length': 2.0, 'air_absorption': True},
        'audio': {'sample_rate': 48000, 'block_size': 512},
    }


def run(build, scene_path, folder, estimator, seed, rays, budget_mb):
    tag = f'{estimator}-{seed}'
    wav, csv = os.path.join(folder, tag + '.wav'), os.path.join(folder, tag + '.csv')
    cmd = [os.path.join(build, 'apps', 'dpc-demo'), scene_path, '--offline', wav, '--duration',
           '3', '--rays', str(rays), '--seed', str(seed), '--estimator', estimator,
           '--er-out', csv, '--cache-memory-mb', str(budget_mb)]
    done = subprocess.run(cmd, check=True, capture_output=True, text=True)
    lines = done.stdout.splitlines()
    summary = [line for line in lines if line.startswith('cache') or 'cache entries' in line]
    analysis = subprocess.run([os.path.join(build, 'apps', 'dpc-analyze'), csv, '--json'],
                              check=True, capture_output=True, text=True)
    return json.loads(analysis.stdout), summary


def band_values(analysis, param):
    return [band[param] for band in analysis['sources'][0]['bands']]


def plot(files, image):
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    targets = {'g': (0.3, 'G, DPC − PT (dB)'), 'c80': (0.5, 'C80, DPC − PT (dB)'),
               'edt': (5.0, 'EDT, DPC / PT − 1 (%)')}
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.8))
    x = range(len(BANDS))
    for path in files:
        with open(path) as f:
            data = json.load(f)
        for case in data['cases']:
            label = f"{case['room']}, {data['cache_memory_mb']:g} MB"
            for ax, p in zip(axes, PARAMS):
                scale = 100.0 if p == 'edt' else 1.0
                rows = case['comparison'][p]
                ax.errorbar([i for i, r in zip(x, rows) if r],
                            [scale * r['difference'] for r in rows if r],
                            yerr=[scale * r['path_tracing_sd'] / len(case['dpc']) ** 0.5
                                  for r in rows if r], marker='o', capsize=3, label=label)
    for ax, p in zip(axes, PARAMS):
        limit, title = targets[p]
        ax.axhspan(-limit, limit, color='0.92', zorder=0)
        ax.axhline(0, color='0.5', lw=0.8)
        ax.set_xticks(list(x), BANDS, rotation=45)
        ax.set_xlabel('octave band (Hz)')
        ax.set_title(title + f' — target ±{limit:g}')
        ax.set_ylim(-1.2 * limit, 1.2 * limit)
    axes[0].legend(fontsize=8)
    fig.suptitle('DPC vs plain path tracing, 10 × 7 × 3 m shoebox, α = 0.1, 20,000 rays '
                 '(error bars: path tracing σ / √seeds)', fontsize=10)
    fig.tight_layout()
    fig.savefig(image, dpi=110)
    print(f'wrote {image}', file=sys.stderr)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--build', default=os.path.join(ROOT, 'build'))
    ap.add_argument('--seeds', type=int, default=3)
    ap.add_argument('--rays', type=int, default=20000)
    ap.add_argument('--cache-memory-mb', type=float, default=64.0,
                    help='DPC memory budget per source-listener pair (1 forces merging)')
    ap.add_argument('--out', default=os.path.join(ROOT, 'docs', 'data',
                                                  'cache-vs-path-tracing.json'))
    ap.add_argument('--plot', nargs='+', metavar='JSON', help='plot these result files only')
    ap.add_argument('--image', default=os.path.join(ROOT, 'docs', 'images',
                                                    'cache-vs-path-tracing.png'))
    args = ap.parse_args()
    if args.plot:
        plot(args.plot, args.image)
        return
    result = {'rays_per_frame': args.rays, 'seeds': args.seeds,
              'cache_memory_mb': args.cache_memory_mb, 'cases': []}
    with tempfile.TemporaryDirectory() as folder:
        for name, scattering in (('diffuse', 1.0), ('specular', 0.0)):
            path = os.path.join(folder, name + '.json')
            with open(path, 'w') as f:
                json.dump(scene(scattering), f)
            case = {'room': name, 'scattering': scattering}
            for estimator in ('dpc', 'path_tracing'):
                runs = []
                for seed in range(1, args.seeds + 1):
                    print(f'{name} {estimator} seed {seed}', file=sys.stderr)
                    analysis, summary = run(args.build, path, folder, estimator, seed, args.rays,
                                            args.cache_memory_mb)
                    runs.append({p: band_values(analysis, p) for p in PARAMS})
                    if estimator == 'dpc':
                        case['dpc_summary'] = summary
                case[estimator] = runs
            # Mean over seeds per band; path tracing's standard deviation over seeds is the
            # Monte Carlo error of one path-tracing frame.
            diff = {}
            for p in PARAMS:
                rows = []
                for b in range(len(BANDS)):
                    dv = [r[p][b] for r in case['dpc']]
                    pv = [r[p][b] for r in case['path_tracing']]
                    if any(v is None or isinstance(v, str) for v in dv + pv):
                        rows.append(None)
                        continue
                    dm, pm = statistics.mean(dv), statistics.mean(pv)
                    sd = statistics.stdev(pv) if len(pv) > 1 else float('nan')
                    delta = dm - pm if p != 'edt' else dm / pm - 1.0
                    rows.append({'dpc': dm, 'path_tracing': pm, 'difference': delta,
                                 'path_tracing_sd': sd})
                diff[p] = rows
            case['comparison'] = diff
            result['cases'].append(case)
    os.makedirs(os.path.dirname(args.out), exist_ok=True)
    with open(args.out, 'w') as f:
        json.dump(result, f, indent=1)
    print('| room | parameter | ' + ' | '.join(BANDS) + ' |')
    print('|---|---|' + '---|' * len(BANDS))
    for case in result['cases']:
        for p in PARAMS:
            cells = []
            for row in case['comparison'][p]:
                if row is None:
                    cells.append('—')
                elif p == 'edt':
                    cells.append(f"{100 * row['difference']:+.1f} %")
                else:
                    cells.append(f"{row['difference']:+.2f} dB")
            unit = ' (DPC / PT − 1)' if p == 'edt' else ' (DPC − PT)'
            print(f"| {case['room']} | {p.upper()}{unit} | " + ' | '.join(cells) + ' |')


if __name__ == '__main__':
    main()
