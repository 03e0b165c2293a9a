"""The glTF oracle corpus (tests/gltf/oracle_test.py): a level (the shoebox of scenes/shoebox.obj
with a door node swung by an animation, written by scenes/gltffile.py), its valid variants, and
mutations of it, each written into its own folder with a scene JSON (scene.json) that names it.

Each case is (name, make, dpc) in CASES: make(folder) writes the level and whatever it needs
there and returns the level's file name; dpc is None when dpc must load the level, else a text
its one-line refusal must contain. The cases of tests/gltf/mutations.py are added to CASES.

  corpus.py OUT_FOLDER [NAME...]   writes the cases (all when none is named) into OUT_FOLDER/NAME
"""
import json
import os
import struct
import sys
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, '..', '..'))
sys.path.insert(0, os.path.join(ROOT, 'scenes'))
from gltffile import (Gltf, read_obj, BYTE, UINT8, SHORT, UINT16, UINT32, FLOAT,  # noqa: E402
                      TRIANGLES)

SHOEBOX_OBJ = os.path.join(ROOT, 'scenes', 'shoebox.obj')
# The dry signal the cases' scenes name: write_click's file (main and the tests set it).
SIGNAL = None


def write_click(path):
    """A 0.1 s mono 48 kHz WAV holding one click: a short signal loads fast."""
    import wave
    with wave.open(path, 'wb') as w:
        w.setnchannels(1)
        w.setsampwidth(2)
        w.setframerate(48000)
        w.writeframes(struct.pack('<4800h', 8000, *([0] * 4799)))
DOOR_QUARTER_TURN = [(0, 0, 0, 1), (0, 0.70710677, 0, 0.70710677)]


def scene_json(level, objects=('door',)):
    """The scene naming `level`: the shoebox's materials, a talker and a listener inside the
    room, the door as a moving object, and a cheap propagation (the test loads, not listens)."""
    absorption = {'walls': 0.1, 'floor': 0.3, 'ceiling': 0.2}
    return {'mesh': level,
            'materials': {m: {'absorption': a, 'scattering': 0.2} for m, a in absorption.items()},
            'sources': [{'name': 'talker', 'position': [2, 1.6, 3.5], 'signal': SIGNAL}],
            'listener': {'position': [8.5, 1.6, 1.5], 'radius': 0.5},
            'objects': [{'name': o} for o in objects],
            'propagation': {'rays_per_frame': 64, 'max_order': 8, 'exact_order': 0,
                            'ir_length': 0.2}}


class Level:
    """The shoebox level being built: g (a gltffile.Gltf), the material indices by name, the
    room's node and the door's node, mesh and animation (None without a door)."""

    def __init__(self, door=True, interpolation='LINEAR', path='rotation'):
        self.g = Gltf()
        self.materials = {}
        runs = read_obj(SHOEBOX_OBJ)
        self.room = self.g.node('room', mesh=self.g.mesh(
            'room', [(self.material(m), p, t) for m, p, t in runs]))
        self.door = None
        if door:
            leaf = [(self.material('walls'), [(0, 0, 0), (0, 2, 0), (0, 2, 1), (0, 0, 1)],
                     [(0, 1, 2), (0, 2, 3)])]
            self.door = self.g.node('door', mesh=self.g.mesh('door', leaf), translation=[5, 0, 3])
            values = DOOR_QUARTER_TURN if path == 'rotation' else [(5, 0, 3), (5, 0, 4)]
            if interpolation == 'CUBICSPLINE':
                zero = (0,) * len(values[0])
                values = [v for key in values for v in (zero, key, zero)]
            self.g.animation('swing', [(self.door, path, [0, 1], values, interpolation)])

    def material(self, name):
        if name not in self.materials:
            self.materials[name] = self.g.material(name)
        return self.materials[name]

    @property
    def doc(self):
        return self.g.doc

    def primitive(self, mesh=0, k=0):
        return self.g.doc['meshes'][mesh]['primitives'][k]

    def accessor_of(self, attribute='POSITION', mesh=0, k=0):
        p = self.primitive(mesh, k)
        return self.g.doc['accessors'][p['attributes'][attribute] if attribute != 'indices'
                                       else p['indices']]

    def add_primitive(self, positions, indices=None, mode=TRIANGLES, component=UINT32,
                      material='floor', **attributes):
        """Adds a primitive to the room's mesh (a patch lying on the floor, y = 0.001)."""
        p = {'attributes': {'POSITION': self.g.accessor([c for v in positions for c in v], 'VEC3',
                                                        bounds=True), **attributes},
             'mode': mode, 'material': self.material(material)}
        if indices is not None:
            p['indices'] = self.g.accessor(list(indices), 'SCALAR', component)
        self.g.doc['meshes'][0]['primitives'].append(p)
        return p

    def save(self, folder, name='level.glb'):
        self.g.save(os.path.join(folder, name))
        return name


def write_scene(folder, level, objects=('door',)):
    with open(os.path.join(folder, 'scene.json'), 'w') as f:
        json.dump(scene_json(level, objects), f, indent=1)


# A 4 x 4 m patch on the floor (0.001 m above it), in several topologies.
PATCH = [(3, 0.001, 1), (3, 0.001, 5), (7, 0.001, 1), (7, 0.001, 5)]


def png_1x1():
    """A valid 1 x 1 grey PNG (signature, IHDR, IDAT, IEND with their CRCs)."""
    def chunk(kind, data):
        return (struct.pack('>I', len(data)) + kind + data +
                struct.pack('>I', zlib.crc32(kind + data) & 0xFFFFFFFF))
    ihdr = struct.pack('>IIBBBBB', 1, 1, 8, 0, 0, 0, 0)
    return (b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', ihdr) +
            chunk(b'IDAT', zlib.compress(b'\x00\x80')) + chunk(b'IEND', b''))


def gltf_with(edit=None, name='level.glb', objects=('door',), **level):
    """A case: the level (Level(**level)), edited by edit(level) before it is saved as NAME."""
    def make(folder):
        lv = Level(**level)
        if edit:
            edit(lv)
        saved = lv.save(folder, name)
        write_scene(folder, saved, objects)
        return saved
    return make


def valid_cases():
    """Levels dpc loads, each a different correct way of writing one."""
    def strip(lv):
        lv.add_primitive(PATCH, [0, 1, 2, 3], mode=5)

    def fan(lv):
        lv.add_primitive([PATCH[0], PATCH[1], PATCH[3], PATCH[2]], [0, 1, 2, 3], mode=6)

    def no_indices(lv):
        lv.add_primitive([PATCH[0], PATCH[1], PATCH[2], PATCH[2], PATCH[1], PATCH[3]])

    def small_indices(component):
        return lambda lv: lv.add_primitive(PATCH, [0, 1, 2, 2, 1, 3], component=component)

    def texcoords(lv):
        # Two bytes per element, padded to four: vertex data is 4-byte aligned.
        view = lv.g._view(b''.join(struct.pack('<BBxx', u, v)
                                   for u, v in [(0, 0), (0, 255), (255, 0), (255, 255)]))
        lv.doc['bufferViews'][view]['byteStride'] = 4
        lv.doc['accessors'].append({'bufferView': view, 'componentType': UINT8, 'count': 4,
                                    'type': 'VEC2', 'normalized': True})
        lv.add_primitive(PATCH, [0, 1, 2, 2, 1, 3], TEXCOORD_0=len(lv.doc['accessors']) - 1)

    def interleaved(lv):
        data = b''.join(struct.pack('<6f', *p, 0, 1, 0) for p in PATCH)
        view = lv.g._view(data)
        lv.doc['bufferViews'][view]['byteStride'] = 24
        lv.doc['accessors'] += [
            {'bufferView': view, 'componentType': FLOAT, 'count': 4, 'type': 'VEC3',
             'min': [3, 0.001, 1], 'max': [7, 0.001, 5]},
            {'bufferView': view, 'byteOffset': 12, 'componentType': FLOAT, 'count': 4,
             'type': 'VEC3'}]
        n = len(lv.doc['accessors'])
        lv.doc['meshes'][0]['primitives'].append({
            'attributes': {'POSITION': n - 2, 'NORMAL': n - 1}, 'material': lv.material('floor'),
            'indices': lv.g.accessor([0, 1, 2, 2, 1, 3], 'SCALAR', UINT32)})

    def matrix_room(lv):
        # The room mirrored in x (scale -1) and moved back by 10 m: the same box.
        lv.doc['nodes'][lv.room]['matrix'] = [-1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 10, 0, 0, 1]

    def textured(lv):
        import base64
        lv.doc['images'] = [{'uri': 'data:image/png;base64,' +
                             base64.b64encode(png_1x1()).decode()}]
        lv.doc['textures'] = [{'source': 0}]
        uv = lv.g.accessor([0, 0, 0, 1, 1, 0, 1, 1], 'VEC2')
        p = lv.add_primitive(PATCH, [0, 1, 2, 2, 1, 3], TEXCOORD_0=uv)
        p['material'] = len(lv.doc['materials'])
        lv.doc['materials'].append({'name': 'floor',
                                    'pbrMetallicRoughness': {'baseColorTexture': {'index': 0}}})

    def step_translation(lv):
        lv.doc['animations'][0]['samplers'][0]['interpolation'] = 'STEP'

    return [
        ('valid_glb', gltf_with(), None),
        ('valid_gltf_bin', gltf_with(name='level.gltf'), None),
        ('valid_data_uri', data_uri_level, None),
        ('valid_uri_percent_escaped', escaped_uri_level, None),
        ('valid_uri_subfolder', subfolder_uri_level, None),
        ('valid_step', gltf_with(interpolation='STEP'), None),
        ('valid_translation_step', gltf_with(step_translation, path='translation'), None),
        ('valid_triangle_strip', gltf_with(strip), None),
        ('valid_triangle_fan', gltf_with(fan), None),
        ('valid_no_indices', gltf_with(no_indices), None),
        ('valid_ubyte_indices', gltf_with(small_indices(UINT8)), None),
        ('valid_ushort_indices', gltf_with(small_indices(UINT16)), None),
        ('valid_texcoord_ubyte_normalized', gltf_with(texcoords), None),
        ('valid_interleaved_stride', gltf_with(interleaved), None),
        ('valid_matrix_node', gltf_with(matrix_room), None),
        ('valid_nested_100', gltf_with(lambda lv: nest(lv, 100)), None),
        ('valid_png_data_uri', gltf_with(textured), None),
        ('valid_unknown_chunk_after_bin', unknown_chunk_level, None),
        ('valid_door_level', door_level, None),
    ]


def data_uri_level(folder):
    import base64
    lv = Level()
    name = lv.save(folder, 'level.gltf')
    path = os.path.join(folder, name)
    doc = json.load(open(path))
    blob = open(os.path.join(folder, 'level.bin'), 'rb').read()
    os.remove(os.path.join(folder, 'level.bin'))
    doc['buffers'][0]['uri'] = ('data:application/octet-stream;base64,' +
                                base64.b64encode(blob).decode())
    json.dump(doc, open(path, 'w'))
    write_scene(folder, name)
    return name


def moved_buffer(folder, target, uri):
    """A .gltf level whose buffer file is moved to `target` (relative to folder) and named by
    `uri` in the JSON."""
    lv = Level()
    name = lv.save(folder, 'level.gltf')
    os.makedirs(os.path.dirname(os.path.join(folder, target)), exist_ok=True)
    os.rename(os.path.join(folder, 'level.bin'), os.path.join(folder, target))
    doc = json.load(open(os.path.join(folder, name)))
    doc['buffers'][0]['uri'] = uri
    json.dump(doc, open(os.path.join(folder, name), 'w'))
    write_scene(folder, name)
    return name


def escaped_uri_level(folder):
    return moved_buffer(folder, 'level data.bin', 'level%20data.bin')


def subfolder_uri_level(folder):
    return moved_buffer(folder, os.path.join('data', 'level.bin'), 'data/level.bin')


def unknown_chunk_level(folder):
    """The .glb with a third chunk of an unknown type after BIN (readers ignore it)."""
    name = gltf_with()(folder)
    path = os.path.join(folder, name)
    data = bytearray(open(path, 'rb').read()) + struct.pack('<I4s', 4, b'XTRA') + b'\0' * 4
    data[8:12] = struct.pack('<I', len(data))
    open(path, 'wb').write(bytes(data))
    return name


def door_level(folder):
    """scenes/door_level.glb as scenes/generate_door_level.py writes it, with its scene."""
    import subprocess
    subprocess.run([sys.executable, os.path.join(ROOT, 'scenes', 'generate_door_level.py'),
                    folder], check=True)
    doc = json.load(open(os.path.join(folder, 'door_level.json')))
    os.remove(os.path.join(folder, 'door_level.json'))
    for source in doc['sources']:
        source['signal'] = SIGNAL
    doc['propagation'].update({'rays_per_frame': 64, 'max_order': 8, 'exact_order': 0,
                               'ir_length': 0.2})
    json.dump(doc, open(os.path.join(folder, 'scene.json'), 'w'))
    return 'door_level.glb'


def design_cases():
    """Levels glTF 2.0 allows that dpc refuses by design, with the text of its refusal (the
    oracle test lists why each is refused)."""
    def mode(m):
        return lambda lv: lv.primitive().update(mode=m)

    def quantized(lv):
        lv.doc['extensionsUsed'] = ['KHR_mesh_quantization']
        lv.doc['extensionsRequired'] = ['KHR_mesh_quantization']
        p = lv.add_primitive(PATCH, [0, 1, 2, 2, 1, 3])
        corners = [(3, 0, 1), (3, 0, 5), (7, 0, 1), (7, 0, 5)]
        view = lv.g._view(b''.join(struct.pack('<3hxx', *c) for c in corners))
        lv.doc['bufferViews'][view]['byteStride'] = 8  # vertex data is 4-byte aligned
        lv.doc['accessors'].append({'bufferView': view, 'componentType': SHORT, 'count': 4,
                                    'type': 'VEC3', 'min': [3, 0, 1], 'max': [7, 0, 5]})
        p['attributes']['POSITION'] = len(lv.doc['accessors']) - 1

    def short_rotation(lv):
        out = lv.doc['animations'][0]['samplers'][0]
        out['output'] = lv.g.accessor([0, 0, 0, 32767, 0, 23170, 0, 23170], 'VEC4', SHORT,
                                      normalized=True)

    def sparse(lv):
        a = lv.accessor_of()
        a['sparse'] = {'count': 1,
                       'indices': {'bufferView': lv.g._view(struct.pack('<I', 0)),
                                   'componentType': UINT32},
                       'values': {'bufferView': lv.g._view(struct.pack('<3f', 0, 0, 0))}}

    def morph(lv):
        lv.primitive(1)['targets'] = [{'POSITION': lv.g.accessor(
            [0.0] * 3 * lv.accessor_of(mesh=1)['count'], 'VEC3', bounds=True)}]

    def outside_buffer(folder):
        os.makedirs(os.path.join(folder, 'level'))
        name = moved_buffer(folder, 'outside.bin', '../outside.bin')
        os.rename(os.path.join(folder, name), os.path.join(folder, 'level', name))
        write_scene(folder, 'level/' + name)
        return 'level/' + name

    def symlinked_buffer(folder):
        name = outside_buffer(folder)
        os.symlink('../outside.bin', os.path.join(folder, 'level', 'level.bin'))
        doc = json.load(open(os.path.join(folder, name)))
        doc['buffers'][0]['uri'] = 'level.bin'
        json.dump(doc, open(os.path.join(folder, name), 'w'))
        return name

    def channel_without_node(lv):
        del lv.doc['animations'][0]['channels'][0]['target']['node']

    def without_position(lv):
        p = lv.add_primitive(PATCH, [0, 1, 2, 2, 1, 3])
        p['attributes']['_CORNER'] = p['attributes'].pop('POSITION')

    def zero_normals(lv):
        lv.primitive()['attributes']['NORMAL'] = len(lv.doc['accessors'])
        lv.doc['accessors'].append({'componentType': FLOAT, 'count': lv.accessor_of()['count'],
                                    'type': 'VEC3'})

    return [
        ('design_mode_points', gltf_with(mode(0)), '(POINTS) is not supported'),
        ('design_mode_lines', gltf_with(mode(1)), '(LINES) is not supported'),
        ('design_mode_line_loop', gltf_with(mode(2)), '(LINE_LOOP) is not supported'),
        ('design_mode_line_strip', gltf_with(mode(3)), '(LINE_STRIP) is not supported'),
        ('design_cubic_spline', gltf_with(interpolation='CUBICSPLINE'), 'CUBICSPLINE'),
        ('design_animated_scale', gltf_with(path='scale'), 'no animated scale'),
        ('design_animation_of_static_node', gltf_with(objects=()), 'which the scene does not name'),
        ('design_quantized_positions', gltf_with(quantized), 'KHR_mesh_quantization'),
        ('design_short_normalized_rotation', gltf_with(short_rotation),
         'normalized integer rotations are not supported'),
        ('design_sparse_accessor', gltf_with(sparse), 'sparse accessors are not supported'),
        ('design_morph_target', gltf_with(morph), 'morph targets are not supported'),
        ('design_buffer_outside_folder', outside_buffer, "lies outside the level's folder"),
        ('design_buffer_symlink_outside', symlinked_buffer, "lies outside the level's folder"),
        ('design_node_depth_200', gltf_with(lambda lv: nest(lv, 200)), 'levels deep'),
        ('design_channel_without_node', gltf_with(channel_without_node),
         'dpc reads only channels that move a node'),
        ('design_primitive_without_position', gltf_with(without_position),
         'a primitive without positions'),
        ('design_accessor_without_buffer_view', gltf_with(zero_normals),
         'an accessor without a bufferView'),
    ]


def nest(lv, depth):
    """Puts the room under a chain of depth - 1 group nodes (the room at depth `depth`)."""
    child = lv.room
    for k in range(depth - 1):
        child = lv.g.node('group%d' % k, children=[child])


def all_cases():
    from mutations import invalid_cases
    return valid_cases() + design_cases() + invalid_cases()


def main():
    global SIGNAL
    out = sys.argv[1]
    names = set(sys.argv[2:])
    os.makedirs(out, exist_ok=True)
    SIGNAL = os.path.join(os.path.abspath(out), 'click.wav')
    write_click(SIGNAL)
    for name, make, _ in all_cases():
        if names and name not in names:
            continue
        folder = os.path.join(out, name)
        os.makedirs(folder)
        make(folder)


if __name__ == '__main__':
    main()
