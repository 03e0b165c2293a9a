"""Writes glTF 2.0 files (.glb, or .gltf with a separate .bin) for the scene generators and the
tests: triangle meshes with named materials, a node tree with transforms, and animations.

    g = Gltf()
    m = g.material('walls')
    mesh = g.mesh('room', [(m, positions, triangles)])      # positions: (x, y, z) metres
    door = g.node('door', mesh=..., translation=[6, 0, 3.5], rotation=[0, 0.7, 0, 0.7])
    g.node('level', children=[door])                         # every parentless node is a root
    g.animation('swing', [(door, 'rotation', times, values, 'LINEAR')])
    g.save('level.glb')

Only what dpc reads is written (no normals, no textures); the JSON part can be edited before
save() through g.doc to make broken files for the tests.
"""
import json
import math
import struct

BYTE, UINT8, SHORT, UINT16, UINT32, FLOAT = 5120, 5121, 5122, 5123, 5125, 5126
TRIANGLES = 4
PACK = {BYTE: 'b', UINT8: 'B', SHORT: 'h', UINT16: 'H', UINT32: 'I', FLOAT: 'f'}
WIDTH = {'SCALAR': 1, 'VEC2': 2, 'VEC3': 3, 'VEC4': 4, 'MAT2': 4, 'MAT3': 9, 'MAT4': 16}


class Gltf:
    def __init__(self):
        self.doc = {'asset': {'version': '2.0', 'generator': 'dpc scenes/gltffile.py'},
                    'scene': 0, 'scenes': [{'nodes': []}], 'nodes': [], 'meshes': [],
                    'materials': [], 'accessors': [], 'bufferViews': [], 'buffers': []}
        self.blob = bytearray()

    def _view(self, data):
        while len(self.blob) % 4:
            self.blob.append(0)
        self.doc['bufferViews'].append({'buffer': 0, 'byteOffset': len(self.blob),
                                        'byteLength': len(data)})
        self.blob += data
        return len(self.doc['bufferViews']) - 1

    def accessor(self, values, kind, component=FLOAT, bounds=False, normalized=False):
        """values: a flat list; kind 'SCALAR', 'VEC2' .. 'MAT4'; component one of BYTE .. FLOAT
        (values as stored: integers for the integer types). Returns the accessor index."""
        width = WIDTH[kind]
        fmt = '<%d%s' % (len(values), PACK[component])
        a = {'bufferView': self._view(struct.pack(fmt, *values)), 'componentType': component,
             'count': len(values) // width, 'type': kind}
        if normalized:
            a['normalized'] = True
        if bounds:  # required for POSITION and animation inputs
            cols = [values[i::width] for i in range(width)]
            finite = [[x for x in c if math.isfinite(x)] or [0.0] for c in cols]
            a['min'] = [min(c) for c in finite]
            a['max'] = [max(c) for c in finite]
        self.doc['accessors'].append(a)
        return len(self.doc['accessors']) - 1

    def material(self, name):
        self.doc['materials'].append({'name': name})
        return len(self.doc['materials']) - 1

    def mesh(self, name, primitives):
        """primitives: (material index or None, [(x, y, z)], [(i, j, k)] 0-based)."""
        prims = []
        for material, positions, triangles in primitives:
            p = {'attributes': {'POSITION': self.accessor([c for v in positions for c in v],
                                                          'VEC3', bounds=True)},
                 'indices': self.accessor([i for t in triangles for i in t], 'SCALAR', UINT32),
                 'mode': TRIANGLES}
            if material is not None:
                p['material'] = material
            prims.append(p)
        self.doc['meshes'].append({'name': name, 'primitives': prims})
        return len(self.doc['meshes']) - 1

    def node(self, name, mesh=None, children=(), **trs):
        """trs: translation [x, y, z], rotation [x, y, z, w], scale [x, y, z], or matrix."""
        n = {'name': name, **trs}
        if mesh is not None:
            n['mesh'] = mesh
        if children:
            n['children'] = list(children)
        self.doc['nodes'].append(n)
        return len(self.doc['nodes']) - 1

    def animation(self, name, channels):
        """channels: (node, 'translation' | 'rotation' | 'scale', times s, values (tuples),
        'LINEAR' | 'STEP')."""
        anim = {'name': name, 'channels': [], 'samplers': []}
        for node, path, times, values, interpolation in channels:
            kind = 'VEC4' if path == 'rotation' else 'VEC3'
            anim['samplers'].append({
                'input': self.accessor(list(times), 'SCALAR', bounds=True),
                'output': self.accessor([c for v in values for c in v], kind),
                'interpolation': interpolation})
            anim['channels'].append({'sampler': len(anim['samplers']) - 1,
                                     'target': {'node': node, 'path': path}})
        self.doc.setdefault('animations', []).append(anim)

    def _roots(self):
        children = {c for n in self.doc['nodes'] for c in n.get('children', [])}
        return [i for i in range(len(self.doc['nodes'])) if i not in children]

    def save(self, path):
        """.glb: one binary file; .gltf: JSON plus PATH-without-extension.bin beside it."""
        self.doc['scenes'][0]['nodes'] = self._roots()
        if path.endswith('.gltf'):
            bin_path = path[:-5] + '.bin'
            self.doc['buffers'] = [{'uri': bin_path.rsplit('/', 1)[-1],
                                    'byteLength': len(self.blob)}]
            with open(bin_path, 'wb') as f:
                f.write(self.blob)
            with open(path, 'w') as f:
                json.dump(self.doc, f, indent=1)
            return
        self.doc['buffers'] = [{'byteLength': len(self.blob)}]
        text = json.dumps(self.doc, separators=(',', ':')).encode()
        text += b' ' * (-len(text) % 4)
        blob = bytes(self.blob) + b'\0' * (-len(self.blob) % 4)
        with open(path, 'wb') as f:
            f.write(struct.pack('<4sII', b'glTF', 2, 12 + 8 + len(text) + 8 + len(blob)))
            f.write(struct.pack('<I4s', len(text), b'JSON') + text)
            f.write(struct.pack('<I4s', len(blob), b'BIN\0') + blob)


def read_obj(path):
    """The (material, positions, triangles) runs of an OBJ file as scenes/objfile.py writes it:
    one run per usemtl line, each with the vertices it uses (0-based, in order of first use)."""
    verts, runs = [], []
    for line in open(path):
        w = line.split()
        if not w:
            continue
        if w[0] == 'v':
            verts.append(tuple(float(x) for x in w[1:4]))
        elif w[0] == 'usemtl':
            runs.append((w[1], [], [], {}))
        elif w[0] == 'f':
            _, positions, triangles, index = runs[-1]
            tri = []
            for k in (int(x) - 1 for x in w[1:4]):
                if k not in index:
                    index[k] = len(positions)
                    positions.append(verts[k])
                tri.append(index[k])
            triangles.append(tuple(tri))
    return [(m, p, t) for m, p, t, _ in runs]
