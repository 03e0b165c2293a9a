#!/usr/bin/env python3
"""The sound dpc studio gives the page on the offline clock (GET /api/audio, what the "listen"
switch plays through Web Audio) against an instrument outside the studio: the offline renderer's
WAV of the same scene, written by the same dpc-demo run before the studio starts
(`--offline W.wav --gain-db 0`: the raw level, not normalised).

Both render the scene from scene time 0 with the same seed, rays and frames; the session's
sound is late by its callback adapter's one block (LiveSession::adapterLatencyFrames). Measured
on shoebox (one static talker, walking listener) and two_rooms (moving source, door, two
talkers): correlation 0.991-0.998 at a lag of exactly one block, level within 0.04 dB; what is
left is when a new IR takes over (the renderer at its frame's scene time, the session at the
next block). Asserted: the lag is one block, correlation > 0.98, level within 0.25 dB per
channel. A chunk lost or repeated, sound from the wrong scene time, or a gain applied to one
path and not the other breaks one of them.

Usage: page_sound_test.py BUILD_DIR SOURCE_DIR SCENE_NAME
"""
import json
import os
import re
import subprocess
import sys
import tempfile
import time
import urllib.request
import warnings

import numpy as np
import scipy.io.wavfile

SECONDS = 3.0


def fetch_sound(port, token, frames):
    """Polls /api/audio from frame 0 until `frames` frames; checks numbering and contiguity."""
    got, nxt = [], 0
    deadline = time.time() + 300
    while nxt < frames:
        if time.time() > deadline:
            sys.exit(f'FAIL: only {nxt} frames in 300 s')
        with urllib.request.urlopen(f'http://127.0.0.1:{port}/api/audio?from={nxt}&token={token}') as r:
            first, skipped = int(r.headers['X-Dpc-First']), int(r.headers['X-Dpc-Skipped'])
            channels, rate = int(r.headers['X-Dpc-Channels']), int(r.headers['X-Dpc-Sample-Rate'])
            data = np.frombuffer(r.read(), dtype='<f4').reshape(-1, channels)
        if skipped or first != nxt:
            sys.exit(f'FAIL: asked for frame {nxt}, got {first} ({skipped} skipped)')
        got.append(data)
        nxt += len(data)
        time.sleep(0.05)
    return rate, np.concatenate(got)[:frames]


def studio_sound(build, scene, wav):
    demo = subprocess.Popen([f'{build}/apps/dpc-demo', scene, '--studio', '--offline', wav,
                             '--duration', str(SECONDS), '--gain-db', '0', '--output', 'binaural',
                             '--rays', '2048', '--quiet'],
                            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    try:
        line = ''
        while 'studio:' not in line:
            line = demo.stdout.readline()
            if not line and demo.poll() is not None:
                sys.exit(f'FAIL: dpc-demo exited ({demo.returncode}) before serving')
        m = re.search(r'http://127\.0\.0\.1:(\d+)/\?token=([0-9a-f]+)', line)
        return fetch_sound(m.group(1), m.group(2), int(SECONDS * 48000))
    finally:
        demo.send_signal(2)
        demo.wait(60)


def compare(page, wav):
    """Lag (frames, page behind the WAV), correlation and level difference (dB) of one channel."""
    n = min(len(page), len(wav))
    a, b = page[:n].astype(float), wav[:n].astype(float)
    size = 1 << int(np.ceil(np.log2(2 * n)))
    r = np.fft.irfft(np.fft.rfft(a, size) * np.conj(np.fft.rfft(b, size)), size)
    lag = int(np.argmax(np.abs(r)))
    lag = lag if lag < size // 2 else lag - size
    corr = r[lag] / np.sqrt((a * a).sum() * (b * b).sum())
    return lag, corr, 10 * np.log10((a * a).sum() / (b * b).sum())


def main():
    build, source, name = sys.argv[1:4]
    with open(os.path.join(source, 'scenes', name)) as f:
        block = json.load(f).get('audio', {}).get('block_size', 512)  # docs/scene-format.md default
    with tempfile.TemporaryDirectory() as work:
        wav = os.path.join(work, 'render.wav')
        rate, page = studio_sound(build, os.path.join(source, 'scenes', name), wav)
        files = sorted(f for f in os.listdir(work) if f.endswith('.wav'))
        # Several listeners: one file each (render-NAME.wav); the studio plays the first.
        with warnings.catch_warnings():
            warnings.simplefilter('ignore')
            wav_rate, ref = scipy.io.wavfile.read(os.path.join(work, files[0]))
    if wav_rate != rate or ref.shape[1] != page.shape[1]:
        sys.exit(f'FAIL: page {rate} Hz x {page.shape[1]}, WAV {wav_rate} Hz x {ref.shape[1]}')
    failed = False
    for c in range(page.shape[1]):
        lag, corr, level = compare(page[:, c], ref[:, c])
        ok = lag == block and corr > 0.98 and abs(level) < 0.25
        failed |= not ok
        print(f'{name} channel {c}: lag {lag} frames (one block: {block}), correlation {corr:.4f}, '
              f'level {level:+.3f} dB against {files[0]}: {"ok" if ok else "FAIL"}')
    sys.exit(1 if failed else 0)


if __name__ == '__main__':
    main()
