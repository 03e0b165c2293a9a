#!/usr/bin/env python3
"""glTF levels that would cost a loader its stack or its memory are refused before the cost:
dpc-demo on a level whose node tree is 20,000 and 100,000 deep, and on a .glb whose JSON chunk
claims 0xFFFFFFF0 bytes, exits 1 with one line naming the level and the field, having used at
most 1 s of CPU time and 100 MB of memory (peak resident set, from wait4: the process's own
measure, not wall-clock time on a shared machine). Before the checks, the deep trees crashed
the loader (assimp recurses once per level) and the chunk length made assimp allocate 4 GB.

  limits_test.py DPC_DEMO
"""
import os
import re
import struct
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import corpus  # noqa: E402

CPU_LIMIT_S = 1.0
RSS_LIMIT_BYTES = 100 << 20


def deep(depth):
    return corpus.gltf_with(lambda lv: corpus.nest(lv, depth))


def huge_json_chunk(folder):
    name = corpus.gltf_with()(folder)
    path = os.path.join(folder, name)
    data = bytearray(open(path, 'rb').read())
    data[12:16] = struct.pack('<I', 0xFFFFFFF0)
    open(path, 'wb').write(bytes(data))
    return name


CASES = [
    ('node_tree_20000_deep', deep(20000),
     r'^dpc-demo: level\.glb: nodes\[\d+\]: node "group\d+": lies more than 128 levels deep'),
    ('node_tree_100000_deep', deep(100000),
     r'^dpc-demo: level\.glb: nodes\[\d+\]: node "group\d+": lies more than 128 levels deep'),
    ('glb_json_chunk_0xFFFFFFF0', huge_json_chunk,
     r'^dpc-demo: level\.glb: chunks\[0\]\.chunkLength: is 4294967280 bytes'),
]


def run(demo, folder):
    """(exit status, stderr, CPU seconds, peak RSS bytes) of one dpc-demo run."""
    err = os.path.join(folder, 'stderr.txt')
    with open(err, 'w') as stderr:
        p = subprocess.Popen([demo, 'scene.json', '--offline', 'out.wav', '--duration', '0.1'],
                             cwd=folder, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                             stderr=stderr)
        _, status, usage = os.wait4(p.pid, 0)
    p.returncode = os.waitstatus_to_exitcode(status)
    text = open(err).read()
    os.remove(err)
    return p.returncode, text, usage.ru_utime + usage.ru_stime, usage.ru_maxrss * 1024


def main():
    demo = os.path.abspath(sys.argv[1])
    failed = 0
    for name, make, expect in CASES:
        with tempfile.TemporaryDirectory(prefix='dpc_gltf_limits_') as folder:
            corpus.SIGNAL = os.path.join(folder, 'click.wav')
            corpus.write_click(corpus.SIGNAL)
            make(folder)
            status, text, cpu, rss = run(demo, folder)
            lines = [l for l in text.splitlines() if l.startswith('dpc-demo:')]
            problems = []
            if status != 1:
                problems.append('exit status %d, expected 1' % status)
            if len(lines) != 1 or not re.search(expect, lines[0]):
                problems.append('expected one line with %r' % expect)
            if cpu > CPU_LIMIT_S:
                problems.append('%.2f s of CPU time, more than %.0f s' % (cpu, CPU_LIMIT_S))
            if rss > RSS_LIMIT_BYTES:
                problems.append('peak RSS %.0f MB, more than %.0f MB' % (rss / 1e6, RSS_LIMIT_BYTES / 1e6))
            if os.path.exists(os.path.join(folder, 'out.wav')):
                problems.append('out.wav written')
            print('%s %s: exit %d, %.3f s CPU, %.1f MB peak RSS' % (
                'FAIL' if problems else 'ok  ', name, status, cpu, rss / 1e6))
            for p in problems:
                print('     ' + p)
            if problems:
                print('     stderr: ' + text.strip()[-400:])
            failed += bool(problems)
    return 1 if failed else 0


if __name__ == '__main__':
    sys.exit(main())
