#!/bin/sh
# Regenerates the dry test signals in this folder (deterministic for a given espeak-ng).
#   speech.wav      espeak-ng, English, 22050 Hz mono 16-bit (espeak-ng's native rate; the
#                   renderer resamples)
#   percussion.wav  synthesised by make_percussion.py, 48 kHz mono 16-bit
set -eu
cd "$(dirname "$0")"
espeak-ng -v en-us -s 150 -w speech.wav \
  "The quick brown fox jumps over the lazy dog. \
Sound reflects from every wall before it reaches you. \
Listen to the echoes change as you walk."
/usr/bin/python3 make_percussion.py percussion.wav
