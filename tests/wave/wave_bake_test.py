#!/usr/bin/env python3
"""The wave band in the bake (dpc-bake with wave.enabled; docs/wave.md "In the bake"), on a
4.0 x 2.6 x 3.0 m room (alpha 0.2), maximum frequency 250 Hz (crossover 125 Hz), 0.5 s IRs,
probes on a 1 m grid at 1.6 m (12 probes):

  band     the baked wave band at every probe equals dpc-wave's band for listeners at the
           probes' positions (the same grid, the same simulation: bit for bit), and every
           probe of the closed room is reached. With a second closed room beside it (no
           opening) and a probe list with one probe there, that probe is reported in one
           line, stored with wave/reached 0 and zeros, and the bake completes.
  resume   a bake killed (SIGKILL) once while it simulates the wave band and once while it
           bakes probes, then finished with --resume, is the clean bake: h5diff finds no
           difference (and cmp none either: a bake's bytes depend only on its inputs). One
           sample of the wave band changed: playback refuses the file naming /wave/band and
           the source; --resume simulates that source again and gives the clean bytes.
  render   dpc-demo --bake with the listener on a probe, against dpc-demo --ir-out with the
           wave band simulated at that position: the third octaves 31.5-80 Hz within 0.5 dB.
           The two IRs carry the same wave band (bit for bit, `band`) through the same join;
           they differ only in the ray band's reverberant part (the bake's mean of 8 x 4096
           rays per probe, the live cache's estimate), which reaches these thirds through
           the 3rd-order high-pass at |HP|^2 <= (f/fc)^6 / (1 + (f/fc)^6) = 0.12 at the 80 Hz
           third's upper edge (89 Hz): with the ray band's third energy at most 3 times the
           wave band's there and the two estimates within 30 % of each other, at most
           10 log10(1 + 0.12 * 3 * 0.3) = 0.45 dB. The check can fail: the same render from
           the bake with the wave band off (a scene without it) lies more than 3 dB away in
           some third. A scene asking for another wave band (max_frequency 300) is refused
           in one line naming the bake and hash_wave.
  mpi      mpirun -np 3 dpc-bake (rank 0 simulates the wave band while the others bake
           probes) writes the single process's bytes (cmp). Registered only where dpc-bake is
           built with MPI and mpirun is installed.
  cli      a bake of a scene whose wave keys are out of range (max_frequency 5 Hz, a crossover
           above the maximum frequency) or give a grid over the limit (grid_spacing 2 mm: 3.9e9
           nodes, named as wave.grid_spacing, which set it): one line naming the scene
           file and the field, exit status 1, no bake file.

    wave_bake_test.py BUILD_DIR [band|resume|render|mpi|cli ...]
Exit status 0 when every check holds; prints what it measured.
"""
import json
import os
import re
import signal
import subprocess
import sys
import tempfile
import time

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, '..', '..', 'scripts'))
import wave_oracle as oracle  # noqa: E402
from validate_ir import read_wav  # noqa: E402

SIZE = (4.0, 2.6, 3.0)
SOURCE = (1.0, 1.3, 1.0)
failures = []


def check(ok, what):
    print(('ok    ' if ok else 'FAIL  ') + what)
    if not ok:
        failures.append(what)


def tool(build, name):
    return os.path.join(build, 'apps', name)


def room(tmp, name, listeners=((2.5, 1.2, 2.0),), wave=True, **keys):
    """The room's scene with `listeners`, the wave band on or off, per-source rendering."""
    alpha = {w: 0.2 for w in ('x-', 'x+', 'y-', 'y+', 'z-', 'z+')}
    path = oracle.write_box(tmp, name, SIZE, alpha, [SOURCE], list(listeners),
                            dict({'max_frequency': 250}, **keys), ir_length=0.5)
    with open(path) as f:
        scene = json.load(f)
    scene['wave']['enabled'] = wave
    scene['audio'] = {'rendering': 'per_source'}
    scene['sources'][0]['signal'] = os.path.abspath(
        os.path.join(HERE, '..', '..', 'scenes', 'signals', 'speech.wav'))
    with open(path, 'w') as f:
        json.dump(scene, f, indent=1)
    return path


def bake(build, scene, out, *extra):
    done = subprocess.run([tool(build, 'dpc-bake'), scene, '--out', out, '--spacing', '1'] +
                          list(extra), capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit('dpc-bake failed: ' + done.stderr)
    return done.stderr


def band(build, tmp):
    scene = room(tmp, 'band')
    path = os.path.join(tmp, 'band.h5')
    bake(build, scene, path, '--quiet')
    with h5py.File(path, 'r') as f:
        probes = f['probes/position'][:]
        baked = f['wave/band'][0]
        reached = f['wave/reached'][0]
        attrs = dict(f['wave/band'].attrs)
    print('wave/band %s, attributes %s' % (baked.shape, attrs))
    check(reached.all(), 'every probe of the closed room is reached (%d of %d)' %
          (reached.sum(), len(reached)))
    at = room(tmp, 'band_at', listeners=[tuple(map(float, p)) for p in probes])
    out = os.path.join(tmp, 'band.wav')
    done = subprocess.run([tool(build, 'dpc-wave'), at, '--out', out], capture_output=True,
                          text=True)
    if done.returncode != 0:
        sys.exit('dpc-wave failed: ' + done.stderr)
    fs, ir = read_wav(out)
    ir = ir.T.astype(np.float32)
    check(fs == attrs['sample_rate_hz'] and ir.shape == baked.shape,
          'dpc-wave gives the bake\'s shape %s at %d Hz' % (baked.shape, fs))
    if ir.shape == baked.shape:
        diff = float(np.max(np.abs(ir - baked)))
        check(np.array_equal(ir, baked),
              'the baked band at the %d probes equals dpc-wave\'s bit for bit (largest '
              'difference %.3g, largest sample %.3g)' % (len(probes), diff,
                                                         float(np.max(np.abs(baked)))))
    unreached(build, tmp)


def unreached(build, tmp):
    scene = room(tmp, 'two')
    with open(scene) as f:
        desc = json.load(f)
    corners = [(x, y, z) for x in (5.0, 6.0) for y in (0.0, 2.6) for z in (0.0, 3.0)]
    quads = [(1, 2, 4, 3), (5, 7, 8, 6), (1, 5, 6, 2), (3, 4, 8, 7), (1, 3, 7, 5), (2, 6, 8, 4)]
    with open(os.path.join(tmp, desc['mesh']), 'a') as f:
        f.write(''.join('v %r %r %r\n' % c for c in corners) + 'usemtl x-\n')
        f.write(''.join('f %d %d %d\nf %d %d %d\n' % (q[0] + 8, q[1] + 8, q[2] + 8, q[0] + 8,
                                                      q[2] + 8, q[3] + 8) for q in quads))
    probes = os.path.join(tmp, 'two_probes.txt')
    with open(probes, 'w') as f:
        f.write('1.5 1.6 1.5\n5.5 1.3 1.5\n2.5 1.6 2.5\n')
    out = os.path.join(tmp, 'two.h5')
    done = subprocess.run([tool(build, 'dpc-bake'), scene, '--out', out, '--probes', probes],
                          capture_output=True, text=True)
    lines = [l for l in done.stderr.splitlines() if 'no air' in l]
    print('\n'.join(lines))
    with h5py.File(out, 'r') as f:
        reached = list(f['wave/reached'][0])
        silent = not np.any(f['wave/band'][0, 1])
        complete = f.attrs['complete']
    check(done.returncode == 0 and complete == 1, 'the bake with a probe in the closed room '
          'beside completes')
    check(len(lines) == 1 and '1 of 3 probes' in lines[0] and 'probe 1 at 5.500 1.300 1.500'
          in lines[0], 'one line reports the probe the grid does not reach, and counts it')
    check(reached == [1, 0, 1] and silent, 'wave/reached %s, the unreached probe\'s band zeros'
          % reached)


def kill_when(proc, err_path, text, count=1):
    """SIGKILLs proc once its stderr holds `text` `count` times; False if it ended first."""
    while proc.poll() is None:
        with open(err_path) as f:
            if f.read().count(text) >= count:
                proc.send_signal(signal.SIGKILL)
                proc.wait()
                return True
        time.sleep(0.01)
    return False


def resume(build, tmp):
    scene = room(tmp, 'resume')
    slow = ['--rays', '4000', '--threads', '1']
    clean = os.path.join(tmp, 'clean.h5')
    bake(build, scene, clean, '--quiet', *slow)
    for name, text, count in (('in the wave band', 'wave band steps', 1),
                              ('among the probes', ' probes, ', 3)):
        cut = os.path.join(tmp, 'cut.h5')
        err = os.path.join(tmp, 'cut.err')
        if os.path.exists(cut):
            os.remove(cut)
        with open(err, 'w') as e:
            proc = subprocess.Popen([tool(build, 'dpc-bake'), scene, '--out', cut,
                                     '--spacing', '1'] + slow, stderr=e)
        killed = kill_when(proc, err, text, count)
        with h5py.File(cut, 'r') as f:
            state = 'wave/done %s, %d probes done, complete %d' % (
                list(f['wave/done'][:]), int(f['probes/done'][:].sum()), f.attrs['complete'])
        print('killed %s: %s' % (name, state))
        check(killed, 'the bake was killed %s (before it ended)' % name)
        done = subprocess.run([tool(build, 'dpc-bake'), '--resume', cut, '--quiet'],
                              capture_output=True, text=True)
        check(done.returncode == 0, 'dpc-bake --resume finishes it: ' + done.stderr.strip())
        same = subprocess.run(['h5diff', clean, cut], capture_output=True, text=True)
        check(same.returncode == 0, 'h5diff: the resumed bake (killed %s) equals the clean '
              'one%s' % (name, '' if same.returncode == 0 else ': ' + same.stdout[-300:]))
        check(subprocess.run(['cmp', '-s', clean, cut]).returncode == 0,
              'cmp: the same bytes (killed %s)' % name)
    # One sample of the complete bake's wave band changed: refused for playback naming the
    # dataset and source, simulated again by --resume, which gives the clean bytes back.
    with h5py.File(cut, 'r+') as f:
        f['wave/band'][0, 3, 100] += 1.0
    done = subprocess.run([tool(build, 'dpc-demo'), scene, '--offline',
                           os.path.join(tmp, 'damaged.wav'), '--bake', cut, '--quiet'],
                          capture_output=True, text=True)
    print('damaged: ' + done.stderr.strip().splitlines()[-1])
    check(done.returncode == 1 and (cut + ': /wave/band: source 0: CRC-32') in done.stderr,
          'a damaged wave band is refused for playback, naming /wave/band and the source')
    done = subprocess.run([tool(build, 'dpc-bake'), '--resume', cut, '--quiet'],
                          capture_output=True, text=True)
    check(done.returncode == 0 and 'simulating that wave band again' in done.stderr and
          subprocess.run(['cmp', '-s', clean, cut]).returncode == 0,
          '--resume simulates the damaged source again: the clean bytes')


def third_levels(x, fs, centres):
    n = 4 * len(x)
    f = np.fft.rfftfreq(n, 1 / fs)
    p = np.abs(np.fft.rfft(x, n)) ** 2
    return np.array([10 * np.log10(np.sum(p[(f >= c * 2 ** (-1 / 6)) & (f < c * 2 ** (1 / 6))]))
                     for c in centres])


def render_ir(build, scene, tmp, name, *extra):
    """dpc-demo's last IR of the render (its progress on: the wave band's lines show)."""
    ir = os.path.join(tmp, name + '_ir.wav')
    done = subprocess.run([tool(build, 'dpc-demo'), scene, '--offline',
                           os.path.join(tmp, name + '.wav'), '--ir-out', ir, '--duration', '0.6'] +
                          list(extra), capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit('dpc-demo failed: ' + done.stderr)
    fs, x = read_wav(ir)
    return fs, x[:, 0], done.stdout + done.stderr


def render(build, tmp):
    grid = room(tmp, 'render_grid')
    path = os.path.join(tmp, 'render.h5')
    bake(build, grid, path, '--quiet')
    with h5py.File(path, 'r') as f:
        probe = tuple(map(float, f['probes/position'][5]))
    print('listener on probe 5 at %s' % (probe,))
    scene = room(tmp, 'render', listeners=[probe])
    fs, live, live_log = render_ir(build, scene, tmp, 'live')
    _, baked, log = render_ir(build, scene, tmp, 'baked', '--bake', path)
    check('wave band: source 1 of 1' in live_log and 'wave band: source' not in log,
          'the render from the bake plays the bake\'s wave band: it simulates none (the '
          'render without the bake does)')
    played = re.search(r'source responses from the bake (\d+), live 0', log)
    check(bool(played) and int(played.group(1)) > 0,
          'the render played its pair from the bake, every frame')
    centres = [31.5, 40, 50, 63, 80]
    delta = third_levels(baked, fs, centres) - third_levels(live, fs, centres)
    print('thirds %s Hz: from the bake minus simulated %s dB' %
          (centres, ' '.join('%+.2f' % d for d in delta)))
    check(np.max(np.abs(delta)) <= 0.5, 'thirds 31.5-80 Hz within 0.5 dB of the simulated '
          'wave band\'s render (largest %.2f dB)' % np.max(np.abs(delta)))
    off = room(tmp, 'render_off', listeners=[probe], wave=False)
    _, rays, _ = render_ir(build, off, tmp, 'rays', '--bake', path)
    control = third_levels(rays, fs, centres) - third_levels(live, fs, centres)
    print('control, the bake played without the wave band: %s dB' %
          ' '.join('%+.2f' % d for d in control))
    check(np.max(np.abs(control)) > 3.0, 'control: without the wave band some third lies more '
          'than 3 dB away (largest %.2f dB)' % np.max(np.abs(control)))
    other = room(tmp, 'render_other', listeners=[probe], max_frequency=300)
    done = subprocess.run([tool(build, 'dpc-demo'), other, '--offline',
                           os.path.join(tmp, 'other.wav'), '--bake', path, '--quiet'],
                          capture_output=True, text=True)
    print('another maximum frequency: exit %d: %s' % (done.returncode, done.stderr.strip()))
    check(done.returncode == 1 and done.stderr.strip().count('\n') == 0 and
          (path + ': hash_wave: ') in done.stderr, 'a scene asking for another wave band '
          'is refused in one line naming the bake and hash_wave')


def mpi(build, tmp):
    scene = room(tmp, 'mpi')
    alone, shared = os.path.join(tmp, 'alone.h5'), os.path.join(tmp, 'np3.h5')
    bake(build, scene, alone, '--quiet', '--threads', '1')
    done = subprocess.run(['mpirun', '-q', '--allow-run-as-root', '--oversubscribe', '-np', '3',
                           tool(build, 'dpc-bake'), scene, '--out', shared, '--spacing', '1',
                           '--quiet', '--threads', '1'], capture_output=True, text=True)
    print(done.stderr.strip())
    check(done.returncode == 0 and 'wave band of 1 source' in done.stderr,
          'mpirun -np 3 dpc-bake bakes the wave band and the probes')
    check(subprocess.run(['cmp', '-s', alone, shared]).returncode == 0,
          'cmp: mpirun -np 3 writes the single process\'s bytes')


def cli(build, tmp):
    for name, keys, field in (('low', {'max_frequency': 5}, 'wave.max_frequency'),
                              ('crossover', {'crossover_hz': 300}, 'wave.crossover_hz'),
                              ('grid', {'grid_spacing': 0.002}, 'wave.grid_spacing')):
        scene = room(tmp, 'cli_' + name, **keys)
        out = os.path.join(tmp, 'cli_%s.h5' % name)
        done = subprocess.run([tool(build, 'dpc-bake'), scene, '--out', out, '--spacing', '1'],
                              capture_output=True, text=True)
        lines = done.stderr.strip().splitlines()
        print('%s: exit %d: %s' % (name, done.returncode, done.stderr.strip()))
        check(done.returncode == 1 and len(lines) == 1 and lines[0].startswith(
            'dpc-bake: %s: %s: ' % (scene, field)) and not os.path.exists(out),
              '%s: one line naming %s and %s, exit 1, no file' % (name, scene, field))


def spacing(build, tmp):
    """A probe grid coarser than the probes' blend was measured at (0.37 of the wavelength at
    the crossover, rounded up from 1 m at 125 Hz) bakes, with one warning line; the measured 1 m has none."""
    coarse = subprocess.run([tool(build, 'dpc-bake'), room(tmp, 'coarse'), '--out',
                             os.path.join(tmp, 'coarse.h5'), '--spacing', '2', '--quiet'],
                            capture_output=True, text=True)
    warned = [l for l in coarse.stderr.splitlines() if 'warning' in l]
    print('\n'.join(warned))
    # 2 m against 343 / 125 = 2.744 m: 0.73 of it.
    check(coarse.returncode == 0 and len(warned) == 1 and
          'warning: --spacing 2.00 m is 0.73 of the wavelength' in warned[0],
          '--spacing 2 at a 125 Hz crossover: baked, one warning naming --spacing and 0.73')
    fine = bake(build, room(tmp, 'fine'), os.path.join(tmp, 'fine.h5'), '--quiet')
    check('warning' not in fine, '--spacing 1 (as measured): no warning')


def main():
    build = sys.argv[1]
    which = sys.argv[2:] or ['band', 'resume', 'render', 'cli', 'spacing']
    with tempfile.TemporaryDirectory() as tmp:
        for name in which:
            print('== ' + name)
            globals()[name](build, tmp)
    if failures:
        sys.exit('%d checks failed' % len(failures))
    print('all checks hold')


if __name__ == '__main__':
    main()
