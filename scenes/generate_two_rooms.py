#!/usr/bin/python3
"""Generates the two-room door scene: scenes/two_rooms.obj (the rooms), scenes/door.obj (the
door, in its own frame) and scenes/two_rooms.json. Deterministic (same output every run).

Two rooms 6 x 3 x 5 m side by side along x (x 0..6 room A, 6..12 room B; y 0..3 up; z 0..5),
joined by a 1 m wide, 2.1 m high doorway in the partition x = 6 at z 3.5..4.5. The door is a
1 x 2.1 m panel hinged on its vertical edge at z = 3.5: it stands open into room B (turned 90
degrees about +y), swings shut from 4 s to 5 s, stays shut until 9 s and swings open again by
10 s. A talker stands in room A, then walks through the doorway into room B (10.5 .. 14 s); a
percussion source circles in room B (looped, 1.2 m/s). Listener "a" stands in room A, "b" in
room B: "b" hears the talker through the open door, loses most of it while the door is shut,
and hears the talker arrive.

Usage: generate_two_rooms.py [OUT_FOLDER]   (default: this script's folder)
"""
import json
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from objfile import write_obj  # noqa: E402

ROOM_X, HEIGHT, DEPTH = 6.0, 3.0, 5.0
DOOR_Z0, DOOR_W, DOOR_H = 3.5, 1.0, 2.1
out = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.abspath(__file__))

verts, faces = [], []


def quad(a, b, c, d, material):
    """Quad a-b-c-d (counter-clockwise seen from the side it faces), two triangles."""
    base = len(verts) + 1
    verts.extend([a, b, c, d])
    faces.append((material, [(base, base + 1, base + 2), (base, base + 2, base + 3)]))


def panel(a, b, c, d, material):
    """Double-sided quad (a partition seen from both rooms)."""
    quad(a, b, c, d, material)
    quad(a, d, c, b, material)


L = 2 * ROOM_X
# Outer shell, faces pointing into the rooms.
quad((0, 0, 0), (0, 0, DEPTH), (L, 0, DEPTH), (L, 0, 0), 'floor')
quad((0, HEIGHT, 0), (L, HEIGHT, 0), (L, HEIGHT, DEPTH), (0, HEIGHT, DEPTH), 'ceiling')
quad((0, 0, 0), (L, 0, 0), (L, HEIGHT, 0), (0, HEIGHT, 0), 'walls')
quad((0, 0, DEPTH), (0, HEIGHT, DEPTH), (L, HEIGHT, DEPTH), (L, 0, DEPTH), 'walls')
quad((0, 0, 0), (0, HEIGHT, 0), (0, HEIGHT, DEPTH), (0, 0, DEPTH), 'walls')
quad((L, 0, 0), (L, 0, DEPTH), (L, HEIGHT, DEPTH), (L, HEIGHT, 0), 'walls')
# Partition x = ROOM_X with the doorway, in panels that meet at the doorway's corners, so that
# the jambs (the free edges either side of the doorway) end at the lintel's height: edge
# diffraction and the gaps round the closed leaf (engine/diffraction.h) take an edge's length.
X = ROOM_X
Z1 = DOOR_Z0 + DOOR_W
for y0, y1 in ((0, DOOR_H), (DOOR_H, HEIGHT)):
    panel((X, y0, 0), (X, y0, DOOR_Z0), (X, y1, DOOR_Z0), (X, y1, 0), 'partition')
    panel((X, y0, Z1), (X, y0, DEPTH), (X, y1, DEPTH), (X, y1, Z1), 'partition')
panel((X, DOOR_H, DOOR_Z0), (X, DOOR_H, Z1), (X, HEIGHT, Z1), (X, HEIGHT, DOOR_Z0), 'partition')


write_obj(os.path.join(out, 'two_rooms.obj'),
          '# two rooms joined by a doorway; scenes/generate_two_rooms.py\n', verts, faces)

# The door in its own frame: hinge edge on the y axis, leaf along +z, 4 cm thick slab (6
# faces), 2 cm smaller than the doorway all round so that it swings freely.
verts, faces = [], []
w, h, t = DOOR_W - 0.02, DOOR_H - 0.01, 0.04
x0, x1 = -t / 2, t / 2
z0, z1 = 0.01, 0.01 + w
quad((x0, 0, z0), (x0, h, z0), (x0, h, z1), (x0, 0, z1), 'door')   # faces -x
quad((x1, 0, z0), (x1, 0, z1), (x1, h, z1), (x1, h, z0), 'door')   # faces +x
quad((x0, 0, z0), (x1, 0, z0), (x1, h, z0), (x0, h, z0), 'door')   # faces -z (hinge edge)
quad((x0, 0, z1), (x0, h, z1), (x1, h, z1), (x1, 0, z1), 'door')   # faces +z
quad((x0, h, z0), (x1, h, z0), (x1, h, z1), (x0, h, z1), 'door')   # faces +y
quad((x0, 0, z0), (x0, 0, z1), (x1, 0, z1), (x1, 0, z0), 'door')   # faces -y
write_obj(os.path.join(out, 'door.obj'),
          '# door leaf, local frame (hinge on the y axis); scenes/generate_two_rooms.py\n',
          verts, faces)

# The same leaf as one double-sided sheet in the plane x = 0 of its frame (door_leaf.obj): a
# transmitting partition is one surface (engine/transmission.h), which the slab's two faces
# would count twice.
verts, faces = [], []
panel((0, 0, z0), (0, 0, z1), (0, h, z1), (0, h, z0), 'door')
write_obj(os.path.join(out, 'door_leaf.obj'),
          '# door leaf as a double-sided sheet, local frame (hinge on the y axis); '
          'scenes/generate_two_rooms.py\n', verts, faces)

# Talker: first-order fit per octave band (63 Hz .. 8 kHz) of a talker's front-to-back ratio in
# the horizontal plane, read from Chu & Warnock, "Detailed directivity of sound fields around
# human talkers", NRC Canada report IRC-RR-104 (2002): about 0, 1, 2, 4, 6, 8, 10, 12 dB. The
# first-order pattern ((1 - a) + a cos)^2 has front/back = (1 / (1 - 2a))^2, so
# a = (1 - 10^(-FBR/20)) / 2. Only the front-to-back ratio is fitted: a first-order fit, not
# the measured balloon.
TALKER_FBR_DB = [0, 1, 2, 4, 6, 8, 10, 12]
TALKER_A = [round((1 - 10 ** (-f / 20)) / 2, 4) for f in TALKER_FBR_DB]


def yaw_quat(deg):
    """Unit quaternion [x, y, z, w] (glTF order) for a turn of deg degrees about +y."""
    a = math.radians(deg) / 2
    return [0.0, round(math.sin(a), 6), 0.0, round(math.cos(a), 6)]


hinge = [ROOM_X, 0.0, DOOR_Z0]
door_keys = [(0.0, 90), (4.0, 90), (4.5, 45), (5.0, 0), (9.0, 0), (9.5, 45), (10.0, 90)]
circle = []
for k in range(9):  # radius 1.2 m about (9.5, 1.5), 2 pi r / 1.2 m/s = 6.28 s per turn
    a = 2 * math.pi * k / 8
    circle.append({'t': round(k * 2 * math.pi / 8, 4),
                   'position': [round(9.5 + 1.2 * math.cos(a), 4), 1.2,
                                round(1.5 + 1.2 * math.sin(a), 4)]})
scene = {
    '_comment': 'Generated by scenes/generate_two_rooms.py (see its docstring). Materials as '
                'scenes/shoebox.json, from the materials library (materials/library.json); '
                'partition between the rooms: single-leaf stud wall, door: solid-core door, both '
                'with a transmission loss (the outer walls are opaque); talker: first-order fit of '
                'a talker\'s directivity (Chu & Warnock 2002), facing +x.',
    'mesh': 'two_rooms.obj',
    'materials': {
        'walls': {'library': 'plasterboard_on_frame', 'scattering': 0.2},
        'partition': {'library': 'partition_stud_wall_single_leaf', 'scattering': 0.2},
        'floor': 'carpet_6mm_closed_cell_foam',
        'ceiling': 'ceiling_plasterboard_on_battens',
        'door': 'door_solid_core',
    },
    'objects': [{
        'name': 'door', 'mesh': 'door_leaf.obj', 'loop': False,
        'trajectory': [{'t': t, 'position': hinge, 'rotation': yaw_quat(d)}
                       for t, d in door_keys],
    }],
    'sources': [
        {'name': 'talker', 'signal': 'signals/speech.wav', 'loop': True, 'gain_db': 0,
         'directivity': {'a': TALKER_A},
         'trajectory': [{'t': 0.0, 'position': [2.0, 1.6, 2.0]},
                        {'t': 10.5, 'position': [2.0, 1.6, 2.0]},
                        {'t': 12.0, 'position': [5.0, 1.6, 4.0]},
                        {'t': 12.8, 'position': [7.0, 1.6, 4.0]},
                        {'t': 14.0, 'position': [8.0, 1.6, 3.0]}]},
        {'name': 'drums', 'signal': 'signals/percussion.wav', 'loop': True, 'gain_db': -6,
         'trajectory': circle, 'trajectory_loop': True},
    ],
    'listeners': [
        {'name': 'a', 'position': [3.5, 1.6, 1.5], 'radius': 0.5, 'yaw': 0},
        {'name': 'b', 'position': [10.5, 1.6, 3.8], 'radius': 0.5, 'yaw': 180},
    ],
    'propagation': {'rays_per_frame': 4096, 'max_order': 200, 'cache_tau': 0.5,
                    'frame_rate': 15, 'ir_length': 1.5},
}
with open(os.path.join(out, 'two_rooms.json'), 'w') as f:
    json.dump(scene, f, indent=1)
    f.write('\n')
