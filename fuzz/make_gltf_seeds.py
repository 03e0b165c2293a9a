#!/usr/bin/python3
"""Writes the seed corpus of fuzz/gltf_fuzzer.cpp into fuzz/corpus/gltf: small levels from the
glTF oracle corpus (tests/gltf/corpus.py), each self-contained (a .glb, or a .gltf whose buffer
is a data: URI; one reads a patch from the fuzzer's level.bin too): the shoebox with its animated
door as .glb and .gltf, with STEP keys, with triangle strips and fans, with UNSIGNED_BYTE
indices, with an interleaved vertex buffer, a node matrix, a level refused for its POINTS
primitive, and one for its zero rotation. The levels named valid-* must load: ctest
fuzz_replay:gltf fails when the fuzzer refuses one (fuzz/fuzz_report.h).

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
import gltffile  # noqa: E402
import mutations  # noqa: E402

SEEDS = ['valid_glb', 'valid_data_uri', 'valid_step', 'valid_triangle_strip', 'valid_triangle_fan',
         'valid_ubyte_indices', 'valid_interleaved_stride', 'valid_matrix_node',
         'design_mode_points', 'node_zero_rotation']


def external_buffer_seed(out):
    """The shoebox as a .gltf whose own data are a data: URI, plus a patch on the room's mesh
    whose positions and indices are read from level.bin, the fuzzer's 1 KiB of zeros: three
    degenerate triangles, which the loader drops with a warning, so the level loads (a door
    whose rotation keys came from level.bin would be refused for their zero length)."""
    with tempfile.TemporaryDirectory() as d:
        name = corpus.data_uri_level(d)
        doc = json.load(open(os.path.join(d, name)))
    doc['buffers'].append({'uri': 'level.bin', 'byteLength': 1024})
    views, accessors = doc['bufferViews'], doc['accessors']
    views += [{'buffer': 1, 'byteOffset': 0, 'byteLength': 108},   # 9 VEC3 floats
              {'buffer': 1, 'byteOffset': 108, 'byteLength': 36}]  # 9 UINT32 indices
    accessors += [{'bufferView': len(views) - 2, 'componentType': gltffile.FLOAT, 'count': 9,
                   'type': 'VEC3', 'min': [0, 0, 0], 'max': [0, 0, 0]},
                  {'bufferView': len(views) - 1, 'componentType': gltffile.UINT32, 'count': 9,
                   'type': 'SCALAR'}]
    doc['meshes'][0]['primitives'].append(
        {'attributes': {'POSITION': len(accessors) - 2}, 'indices': len(accessors) - 1,
         'mode': gltffile.TRIANGLES, 'material': doc['meshes'][0]['primitives'][0]['material']})
    json.dump(doc, open(os.path.join(out, 'valid-external-buffer.gltf'), 'w'),
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
