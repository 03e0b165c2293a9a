"""The invalid cases of the glTF oracle corpus (tests/gltf/corpus.py): one broken thing each in
the shoebox level (URIs, containers, JSON, buffers, accessors, primitives, nodes, animations),
with the text dpc's one-line refusal must contain."""
import json
import os
import struct

from corpus import Level, PATCH, gltf_with, write_scene, nest, UINT8, UINT16, UINT32, FLOAT, SHORT


def setting(*path_and_value):
    """An edit setting doc[path...] = value (path: keys and indices)."""
    *path, value = path_and_value

    def edit(lv):
        node = lv.doc
        for k in path[:-1]:
            node = node[k]
        node[path[-1]] = value
    return edit


def deleting(*path):
    def edit(lv):
        node = lv.doc
        for k in path[:-1]:
            node = node[k]
        del node[path[-1]]
    return edit


def gltf_uri(uri, keep_bin=True):
    """A .gltf level whose buffer URI is `uri`."""
    def make(folder):
        name = Level().save(folder, 'level.gltf')
        if not keep_bin:
            os.remove(os.path.join(folder, 'level.bin'))
        doc = json.load(open(os.path.join(folder, name)))
        doc['buffers'][0]['uri'] = uri
        json.dump(doc, open(os.path.join(folder, name), 'w'))
        write_scene(folder, name)
        return name
    return make


def text_level(text, name='level.gltf'):
    def make(folder):
        open(os.path.join(folder, name), 'w').write(text)
        write_scene(folder, name)
        return name
    return make


def glb_bytes(edit):
    """The .glb level with edit(bytearray) applied to its bytes."""
    def make(folder):
        name = gltf_with()(folder)
        path = os.path.join(folder, name)
        data = bytearray(open(path, 'rb').read())
        edit(data)
        open(path, 'wb').write(bytes(data))
        return name
    return make


def put32(offset, value):
    def edit(data):
        data[offset:offset + 4] = struct.pack('<I', value)
    return edit


def json_chunk_length(data):
    return struct.unpack('<I', data[12:16])[0]


def bin_data(edit_level, patch):
    """A .gltf level whose .bin gets `patch(lv, blob)` (a bytearray) after edit_level(lv)."""
    def make(folder):
        lv = Level()
        if edit_level:
            edit_level(lv)
        name = lv.save(folder, 'level.gltf')
        path = os.path.join(folder, 'level.bin')
        blob = bytearray(open(path, 'rb').read())
        patch(lv, blob)
        open(path, 'wb').write(bytes(blob))
        write_scene(folder, name)
        return name
    return make


def element_offset(lv, accessor, k):
    a = lv.doc['accessors'][accessor]
    return lv.doc['bufferViews'][a['bufferView']]['byteOffset'] + a.get('byteOffset', 0) + k


def at_float(accessor, k, value):
    """Writes float `value` over component k of an accessor's data."""
    def patch(lv, blob):
        o = element_offset(lv, accessor, 4 * k)
        blob[o:o + 4] = struct.pack('<f', value)
    return patch


def after_save(edit):
    """The .gltf level with edit(doc) applied to its JSON as saved."""
    def make(folder):
        name = Level().save(folder, 'level.gltf')
        doc = json.load(open(os.path.join(folder, name)))
        edit(doc)
        json.dump(doc, open(os.path.join(folder, name), 'w'))
        write_scene(folder, name)
        return name
    return make


def position(lv):
    return lv.primitive()['attributes']['POSITION']


def uri_cases():
    return [
        ('uri_passwd_traversal', gltf_uri('../../../../../../../../etc/passwd'), 'outside'),
        ('uri_absolute_passwd', gltf_uri('/etc/passwd'), 'absolute path'),
        ('uri_http', gltf_uri('http://example.com/level.bin'), 'is a http: URI'),
        ('uri_https', gltf_uri('https://example.com/level.bin'), 'is a https: URI'),
        ('uri_ftp', gltf_uri('ftp://example.com/level.bin'), 'is a ftp: URI'),
        ('uri_file_scheme', gltf_uri('file:///etc/passwd'), 'is a file: URI'),
        ('uri_missing_file', gltf_uri('level.bin', keep_bin=False), "'level.bin' not found"),
        ('uri_bad_escape', gltf_uri('level%zz.bin'), 'malformed %-escape'),
        ('uri_data_bad_base64', gltf_uri('data:application/octet-stream;base64,@@@@'), 'base64'),
        ('uri_data_text_media', gltf_uri('data:text/plain;base64,AAAA'), 'a data: URI must be'),
        ('uri_data_too_short', gltf_uri('data:application/octet-stream;base64,AAAA'),
         'but its data holds 3'),
        ('uri_image_outside', gltf_with(setting('images', [{'uri': '../../secret.png'}])),
         'outside'),
        ('uri_image_http', gltf_with(setting('images', [{'uri': 'http://example.com/a.png'}])),
         'is a http: URI'),
    ]


def container_cases():
    def first_chunk_bin(data):
        data[16:20] = b'BIN\0'
    return [
        ('glb_bad_magic', glb_bytes(lambda d: d.__setitem__(slice(0, 4), b'gltf')), 'header.magic'),
        ('glb_version_1', glb_bytes(put32(4, 1)), 'header.version'),
        ('glb_length_mismatch', glb_bytes(put32(8, 99)), 'header.length'),
        ('glb_json_chunk_4gb', glb_bytes(put32(12, 0xFFFFFFF0)), 'chunks[0].chunkLength'),
        ('glb_json_chunk_unaligned', glb_bytes(lambda d: put32(12, json_chunk_length(d) - 1)(d)),
         'chunks[0].chunkLength'),
        ('glb_bin_chunk_beyond_file',
         glb_bytes(lambda d: put32(20 + json_chunk_length(d), 0x7FFFFFF0)(d)),
         'chunks[1].chunkLength'),
        ('glb_first_chunk_bin', glb_bytes(first_chunk_bin), 'chunks[0].chunkType'),
        ('glb_truncated', glb_bytes(lambda d: d.__delitem__(slice(len(d) - 8, None))),
         'header.length'),
        ('json_truncated', text_level('{"asset": {"version": "2.0"}, "nodes": ['), 'malformed JSON'),
        ('json_array_root', text_level('[1, 2, 3]'), 'not an object'),
        ('json_no_asset', text_level('{"nodes": []}'), 'asset: missing required key'),
        ('json_version_1', gltf_with(setting('asset', 'version', '1.0')), 'asset.version'),
        ('json_duplicate_key', text_level('{"asset": {"version": "2.0", "version": "2.0"}}'),
         'appears twice'),
        ('json_nested_100000', text_level('{"asset":{"version":"2.0"},"extras":' + '[' * 100000 +
                                          ']' * 100000 + '}'), 'nested deeper'),
        ('extension_required_draco',
         gltf_with(lambda lv: lv.doc.update(extensionsUsed=['KHR_draco_mesh_compression'],
                                            extensionsRequired=['KHR_draco_mesh_compression'])),
         'KHR_draco_mesh_compression'),
        ('extension_required_not_used',
         gltf_with(setting('extensionsRequired', ['KHR_materials_unlit'])),
         'not in extensionsUsed'),
    ]


def buffer_cases():
    return [
        ('buffer_length_beyond_file',
         bin_data(None, lambda lv, blob: blob.__delitem__(slice(len(blob) - 8, None))),
         'but its data holds'),
        ('buffer_length_zero', after_save(lambda d: d['buffers'].append(
            {'byteLength': 0, 'uri': 'data:application/octet-stream;base64,'})), 'byteLength'),
        ('buffer_view_beyond_buffer', gltf_with(setting('bufferViews', 0, 'byteLength', 1 << 20)),
         'lie beyond buffer'),
        ('buffer_view_buffer_index', gltf_with(setting('bufferViews', 0, 'buffer', 7)),
         'is not an index of buffers'),
        ('buffer_view_stride_2', gltf_with(setting('bufferViews', 0, 'byteStride', 2)),
         'byteStride'),
        ('buffer_view_stride_300', gltf_with(setting('bufferViews', 0, 'byteStride', 300)),
         'byteStride'),
    ]


def accessor_cases():
    def accessor(key, value, which=position):
        return lambda lv: lv.doc['accessors'][which(lv)].__setitem__(key, value)

    def indices(lv):
        return lv.primitive()['indices']
    return [
        ('accessor_count_beyond_view', gltf_with(accessor('count', 1000)), 'count'),
        ('accessor_count_4g', gltf_with(accessor('count', 0xFFFFFFFF)), 'count'),
        ('accessor_count_zero', gltf_with(accessor('count', 0)), 'count'),
        ('accessor_count_float', gltf_with(accessor('count', 8.0)), 'expected a whole number'),
        ('accessor_offset_beyond', gltf_with(accessor('byteOffset', 4096)), 'count'),
        ('accessor_offset_misaligned', gltf_with(accessor('byteOffset', 2)), 'byteOffset'),
        ('accessor_component_5124', gltf_with(accessor('componentType', 5124)),
         'is not a glTF component type'),
        ('accessor_component_string', gltf_with(accessor('componentType', '5126')),
         'expected a whole number'),
        ('accessor_type_vec5', gltf_with(accessor('type', 'VEC5')), 'is not a glTF accessor type'),
        ('accessor_normalized_float', gltf_with(accessor('normalized', True)), 'normalized'),
        ('accessor_view_index', gltf_with(accessor('bufferView', 99)),
         'is not an index of bufferViews'),
        ('accessor_index_negative', gltf_with(lambda lv: lv.primitive().update(indices=-1)),
         'expected an index'),
        ('position_byte', gltf_with(setting('accessors', 0, 'componentType', 5120)), 'POSITION is'),
        ('position_short_normalized',
         gltf_with(lambda lv: lv.doc['accessors'][0].update(componentType=SHORT, normalized=True)),
         'POSITION is'),
        ('position_uint', gltf_with(setting('accessors', 0, 'componentType', UINT32)), 'POSITION is'),
        ('position_vec2', gltf_with(lambda lv: lv.doc['accessors'][0].update(
            type='VEC2', min=[0, 0], max=[10, 3])), 'POSITION is VEC2 of FLOAT'),
        ('position_vec4', gltf_with(lambda lv: lv.doc['accessors'][0].update(
            type='VEC4', count=3, min=[0, 0, 0, 0], max=[10, 10, 10, 10])),
         'POSITION is VEC4 of FLOAT'),
        ('position_no_bounds', gltf_with(deleting('accessors', 0, 'min')), 'min and max'),
        ('position_nan', bin_data(None, at_float(0, 4, float('nan'))), 'NaN'),
        ('indices_float', gltf_with(accessor('componentType', FLOAT, indices)), 'indices are'),
        ('indices_short', gltf_with(accessor('componentType', SHORT, indices)), 'indices are'),
        ('indices_out_of_range', bin_data(None, index_1e6), 'out-of-range'),
        ('indices_count_not_3n', gltf_with(accessor('count', 4, indices)), 'multiple of 3'),
        ('indices_with_stride', gltf_with(lambda lv: lv.doc['bufferViews'][lv.doc['accessors'][
            indices(lv)]['bufferView']].update(byteStride=4)), 'byteStride'),
    ]


def index_1e6(lv, blob):
    o = element_offset(lv, lv.primitive()['indices'], 0)
    blob[o:o + 4] = struct.pack('<I', 1000000)


def primitive_cases():
    def normal_vec4(lv):
        lv.primitive()['attributes']['NORMAL'] = lv.g.accessor([0.0] * 4 * 8, 'VEC4')

    def texcoord_uint(lv):
        lv.primitive()['attributes']['TEXCOORD_0'] = lv.g.accessor([0] * 2 * 8, 'VEC2', UINT32)

    def count_mismatch(lv):
        lv.primitive()['attributes']['NORMAL'] = lv.g.accessor([0.0, 1.0, 0.0] * 5, 'VEC3')

    def strip_of_two(lv):
        lv.add_primitive(PATCH, [0, 1], mode=5, component=UINT16)
    return [
        ('mode_7', gltf_with(lambda lv: lv.primitive().update(mode=7)), 'is not a glTF primitive mode'),
        ('mode_string', gltf_with(lambda lv: lv.primitive().update(mode='TRIANGLES')),
         'expected a whole number'),
        ('normal_vec4', gltf_with(normal_vec4), 'NORMAL is VEC4'),
        ('texcoord_uint', gltf_with(texcoord_uint), 'TEXCOORD_0 is'),
        ('attribute_count_mismatch', gltf_with(count_mismatch), 'every attribute has one'),
        ('strip_of_two_indices', gltf_with(strip_of_two), 'which takes at least 3'),
        ('material_index', gltf_with(lambda lv: lv.primitive().update(material=40)),
         'is not an index of materials'),
        ('mesh_without_primitives', gltf_with(setting('meshes', 0, 'primitives', [])),
         'at least one primitive'),
        ('draco_primitive', gltf_with(lambda lv: lv.primitive().update(
            extensions={'KHR_draco_mesh_compression': {'bufferView': 0, 'attributes': {}}})),
         'Draco'),
    ]


def node_cases():
    def cycle(lv):
        a = lv.g.node('a')
        b = lv.g.node('b', children=[a])
        lv.doc['nodes'][a]['children'] = [b]

    def two_parents(lv):
        lv.g.node('p1', children=[lv.room])
        lv.doc['nodes'].append({'name': 'p2', 'children': [lv.room]})

    def door_in_group(doc):
        doc['nodes'].append({'name': 'group', 'children': [1]})
        doc['scenes'][0]['nodes'] = [0, 1, 2]
    return [
        ('node_child_index', gltf_with(setting('nodes', 0, 'children', [50])), 'is not an index of nodes'),
        ('node_own_child', gltf_with(setting('nodes', 0, 'children', [0])), 'its own child'),
        ('node_two_parents', gltf_with(two_parents), 'a node has one parent'),
        ('node_cycle', gltf_with(cycle), 'a cycle'),
        ('node_mesh_index', gltf_with(setting('nodes', 0, 'mesh', 9)), 'is not an index of meshes'),
        ('node_zero_rotation', gltf_with(setting('nodes', 1, 'rotation', [0, 0, 0, 0])),
         'has zero length'),
        ('node_rotation_not_unit', gltf_with(setting('nodes', 1, 'rotation', [0, 2, 0, 2])), None),
        ('node_rotation_three_numbers', gltf_with(setting('nodes', 1, 'rotation', [0, 0, 1])),
         'expected an array of 4 numbers'),
        ('node_rotation_huge', gltf_with(setting('nodes', 1, 'rotation', [0, 1e300, 0, 1])),
         'too large'),
        ('node_matrix_and_trs',
         gltf_with(setting('nodes', 1, 'matrix', [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1])),
         'given with a matrix'),
        ('node_matrix_zero_scale', gltf_with(lambda lv: (lv.doc['nodes'][1].pop('translation'),
                                                         lv.doc['nodes'][1].update(matrix=[0] * 16))),
         'is not a translation, rotation and scale'),
        ('node_matrix_skew', gltf_with(setting('nodes', 0, 'matrix',
                                               [1, 0, 0, 0, 0.5, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1])),
         'is not a translation, rotation and scale'),
        ('node_matrix_projection', gltf_with(setting('nodes', 0, 'matrix',
                                                     [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 1, 0, 0, 0, 1])),
         'is not a translation, rotation and scale'),
        ('node_depth_20000', gltf_with(lambda lv: nest(lv, 20000)), 'levels deep'),
        ('scene_node_index', after_save(lambda d: d['scenes'][0].update(nodes=[0, 1, 77])),
         'is not an index of nodes'),
        ('scene_node_twice', after_save(lambda d: d['scenes'][0].update(nodes=[0, 1, 0])),
         'listed twice'),
        ('scene_lists_child', after_save(door_in_group), 'a scene lists roots'),
        ('scene_index', gltf_with(setting('scene', 3)), 'is not an index of scenes'),
        ('node_skin', gltf_with(setting('nodes', 1, 'skin', 0)), 'skinned meshes'),
    ]


def animation_cases():
    def sampler(key, value):
        return setting('animations', 0, 'samplers', 0, key, value)

    def channel(*path_value):
        return setting('animations', 0, 'channels', 0, *path_value)

    def output_count(n):
        def edit(lv):
            out = lv.doc['animations'][0]['samplers'][0]['output']
            lv.doc['accessors'][out]['count'] = n
        return edit

    def input_uint(lv):
        lv.doc['animations'][0]['samplers'][0]['input'] = lv.g.accessor([0, 1], 'SCALAR', UINT32,
                                                                         bounds=True)

    def rotation_as_vec3(lv):
        lv.doc['animations'][0]['samplers'][0]['output'] = lv.g.accessor([0.0] * 6, 'VEC3')

    def duplicate_channel(lv):
        lv.doc['animations'][0]['channels'].append(dict(lv.doc['animations'][0]['channels'][0]))

    def input_of(lv):
        return lv.doc['animations'][0]['samplers'][0]['input']

    def output_of(lv):
        return lv.doc['animations'][0]['samplers'][0]['output']
    return [
        ('anim_input_index', gltf_with(sampler('input', 99)), 'is not an index of accessors'),
        ('anim_output_index', gltf_with(sampler('output', 99)), 'is not an index of accessors'),
        ('anim_input_uint', gltf_with(input_uint), 'key times are'),
        ('anim_input_no_bounds', gltf_with(lambda lv: lv.doc['accessors'][input_of(lv)].pop('min')),
         'min and max'),
        ('anim_output_too_few', gltf_with(output_count(1)), '1 values for 2 keys'),
        ('anim_output_too_many', gltf_with(lambda lv: (output_count(3)(lv), lv.g._view(b'\0' * 64),
                                                       lv.doc['bufferViews'][lv.doc['accessors'][
                                                           output_of(lv)]['bufferView']].update(
                                                           byteLength=48))),
         '3 values for 2 keys'),
        ('anim_interpolation_bouncy', gltf_with(sampler('interpolation', 'BOUNCY')),
         'is not a glTF interpolation'),
        ('anim_rotation_as_vec3', gltf_with(rotation_as_vec3), 'rotation values are VEC3'),
        ('anim_channel_sampler_index', gltf_with(channel('sampler', 5)), 'is not an index of samplers'),
        ('anim_channel_path_colour', gltf_with(channel('target', 'path', 'colour')),
         'is not a glTF animation path'),
        ('anim_channel_node_index', gltf_with(channel('target', 'node', 42)),
         'is not an index of nodes'),
        ('anim_channel_weights', gltf_with(channel('target', 'path', 'weights')), 'morph targets'),
        ('anim_duplicate_channel', gltf_with(duplicate_channel), 'the target of two channels'),
        ('anim_no_channels', gltf_with(setting('animations', 0, 'channels', [])),
         'at least one sampler and one channel'),
        ('anim_times_not_increasing', bin_data(None, lambda lv, blob: at_float(
            input_of(lv), 1, 0.0)(lv, blob)), 'not after the previous'),
        ('anim_time_negative', bin_data(None, lambda lv, blob: at_float(input_of(lv), 0, -1.0)(
            lv, blob)), 'negative'),
        ('anim_zero_quaternion', bin_data(None, lambda lv, blob: [
            at_float(output_of(lv), k, 0.0)(lv, blob) for k in range(4, 8)]), 'zero length'),
        ('anim_nan_key', bin_data(None, lambda lv, blob: at_float(output_of(lv), 5, float('nan'))(
            lv, blob)), 'not finite'),
    ]


def invalid_cases():
    return (uri_cases() + container_cases() + buffer_cases() + accessor_cases() +
            primitive_cases() + node_cases() + animation_cases())
