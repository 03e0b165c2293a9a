#!/usr/bin/python3
"""Writes a dry, deterministic percussive/musical phrase: 48 kHz mono 16-bit WAV, ~6 s.

Clicks, drum-like decaying sine sweeps (kick and tom), a noise snare and Karplus-Strong
plucked strings. Sharp onsets make echoes audible; the plucked notes carry pitch.
Usage: make_percussion.py OUT.wav
"""
import sys
import wave

import numpy as np

RATE = 48000
DURATION = 6.0
rng = np.random.default_rng(12345)
out = np.zeros(int(RATE * DURATION))


def add(t0, x):
    i = int(t0 * RATE)
    n = min(len(x), len(out) - i)
    out[i:i + n] += x[:n]


def click(amp=0.9):
    return amp * np.array([1.0, -0.6, 0.3, -0.1])


def drum(f0, f1, decay, length=0.6, amp=0.8):
    t = np.arange(int(length * RATE)) / RATE
    f = f1 + (f0 - f1) * np.exp(-t / 0.03)            # pitch drops from f0 to f1
    phase = 2 * np.pi * np.cumsum(f) / RATE
    return amp * np.sin(phase) * np.exp(-t / decay)


def snare(length=0.3, amp=0.5):
    t = np.arange(int(length * RATE)) / RATE
    noise = rng.standard_normal(len(t))
    return amp * (0.6 * noise * np.exp(-t / 0.05) + 0.4 * np.sin(2 * np.pi * 190 * t) * np.exp(-t / 0.04))


def pluck(freq, length=1.2, amp=0.5):
    """Karplus-Strong: a noise burst in a delay line with a two-point averaging loop filter."""
    period = int(round(RATE / freq))
    buf = rng.uniform(-1, 1, period)
    n = int(length * RATE)
    y = np.empty(n)
    for i in range(n):
        y[i] = buf[i % period]
        buf[i % period] = 0.996 * 0.5 * (buf[i % period] + buf[(i + 1) % period])
    return amp * y


beat = 0.25  # s (120 bpm eighth notes)
for k in range(4):
    add(k * beat * 0.5, click())
for bar in range(2):
    t0 = 0.5 + bar * 2.0
    add(t0, drum(150, 50, 0.15))
    add(t0 + 2 * beat, snare())
    add(t0 + 3 * beat, drum(150, 50, 0.15))
    add(t0 + 4 * beat, drum(300, 140, 0.12, amp=0.6))
    add(t0 + 5 * beat, drum(260, 110, 0.12, amp=0.6))
    add(t0 + 6 * beat, snare())
notes = [220.0, 261.63, 329.63, 392.0, 329.63, 261.63, 220.0, 164.81]
for k, f in enumerate(notes):
    add(4.4 + k * 0.15, pluck(f, length=0.5 if k < 7 else 0.55))
out /= np.max(np.abs(out)) / 0.89
pcm = np.round(out * 32767).astype("<i2")
with wave.open(sys.argv[1], "wb") as w:
    w.setnchannels(1)
    w.setsampwidth(2)
    w.setframerate(RATE)
    w.writeframes(pcm.tobytes())
