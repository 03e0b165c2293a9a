#!/usr/bin/python3
"""Writes the seed corpus of fuzz/gltf_fuzzer.cpp into fuzz/corpus/gltf: small levels from the
glTF oracle corpus (tests/gltf/corpus.py), each self-contained (a .glb, or a .gltf whose buffer
is a data: URI) but one whose buffer is the fuzzer's level.bin: the shoebox with its animated
door as .glb and .gltf, with STEP keys, with triangle strips and fans, with UNSIGNED_BYTE
indices, with an interleaved vertex buffer, a node matrix, a level refused for its POINTS
primitive, and one for its zero rotation.

Usage: fuzz/make_gltf_seeds.py
"""
import json
import os
import shutil
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, '..', 'tests', 'gltf'))
import corpus  # noqa: E402
import mutations  # noqa: E402

SEEDS = ['valid_glb', 'valid_data_uri', 'valid_step', 'valid_triangle_strip', 'valid_triangle_fan',
         'valid_ubyte_indices', 'valid_interleaved_stride', 'valid_matrix_node',
         'design_mode_points', 'node_zero_rotation']


def external_buffer_seed(out):
    """The shoebox as a .gltf whose buffer is level.bin: the fuzzer's 1 KiB of zeros (its
    accessors read zeros: degenerate triangles, which the loader drops with a warning)."""
    with tempfile.TemporaryDirectory() as d:
        name = corpus.Level().save(d, 'level.gltf')
        doc = json.load(open(os.path.join(d, name)))
        assert doc['buffers'][0]['byteLength'] <= 1024
        doc['buffers'][0]['uri'] = 'level.bin'
        json.dump(doc, open(os.path.join(out, 'external-buffer.gltf'), 'w'),
                  separators=(',', ':'))


def main():
    out = os.path.join(HERE, 'corpus', 'gltf')
    shutil.rmtree(out, ignore_errors=True)
    os.makedirs(out)
    cases = {name: make for name, make, _ in corpus.all_cases()}
    for name in SEEDS:
        with tempfile.TemporaryDirectory() as d:
            level = cases[name](d)
            shutil.copy(os.path.join(d, level), os.path.join(out, name.replace('_', '-') +
                                                            os.path.splitext(level)[1]))
    external_buffer_seed(out)


if __name__ == '__main__':
    main()
