#!/usr/bin/python3
"""Generates scenes/hall.obj: a 30 x 12 x 20 m concert hall (x 0..30 along the hall,
y 0..12 up, z 0..20 across), deterministic (no randomness; same output every run).

Contents: stage (x 0..6, 1 m high, wood), stalls floor, ~600 stall seats and ~200 balcony
seats (each seat = cushion box + backrest box, bottom faces omitted: 20 triangles), a
balcony (x 22..30, slab 4.7..5.0 m, parapet), pillars under the balcony front, pilasters
along the side walls, glass windows high on the side walls, a curtain on the rear wall.
Aisles: central (z 9.25..10.75), sides (z 0..1.2 and 18.8..20), front walkway (x 6..8).
Material names (usemtl) match scenes/hall.json.

Usage: generate_hall.py [OUT.obj] [--subdivide K] [--scene OUT.json]
  OUT.obj        default: hall.obj next to this script
  --subdivide K  split every triangle into 4^K (edge midpoints, shared between neighbours, so
                 the mesh stays watertight); same surfaces and materials, 4^K times the
                 triangles (K = 1, 2, 3: ~65k, ~260k, ~1M). For speed benchmarks
                 (scripts/bench_sweep.sh writes such variants to out/scenes/).
  --scene OUT.json  also write a copy of hall.json (next to this script) whose "mesh" and
                 source "signal" paths are rewritten relative to OUT.json's folder.
K = 0 (the default) writes exactly the committed hall.obj.
"""
import argparse
import json
import os
import sys

LENGTH, HEIGHT, WIDTH = 30.0, 12.0, 20.0
STAGE_X, STAGE_H = 6.0, 1.0
BALC_X, BALC_Y0, BALC_Y1 = 22.0, 4.7, 5.0
GRID = 2.0  # wall/floor/ceiling tiling, m

verts = []      # (x, y, z)
vert_index = {} # rounded (x, y, z) -> 1-based index: coincident corners share a vertex
groups = {}     # material -> list of triangles (1-based vertex indices)


def vert(p):
    key = tuple(round(c, 4) for c in p)
    if key not in vert_index:
        verts.append(key)
        vert_index[key] = len(verts)
    return vert_index[key]


def quad(a, b, c, d, mtl):
    """Quad a-b-c-d (any consistent winding) as two triangles."""
    ia, ib, ic, id_ = (vert(p) for p in (a, b, c, d))
    groups.setdefault(mtl, []).extend([(ia, ib, ic), (ia, ic, id_)])


def box(x0, x1, y0, y1, z0, z1, mtl, skip=()):
    """Axis-aligned box; mtl is a material name or a dict face -> material.
    Faces: '-x', '+x', '-y', '+y', '-z', '+z'; faces in skip are not written."""
    m = mtl if isinstance(mtl, dict) else {f: mtl for f in ('-x', '+x', '-y', '+y', '-z', '+z')}
    faces = {
        '-x': ((x0, y0, z0), (x0, y0, z1), (x0, y1, z1), (x0, y1, z0)),
        '+x': ((x1, y0, z0), (x1, y1, z0), (x1, y1, z1), (x1, y0, z1)),
        '-y': ((x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1)),
        '+y': ((x0, y1, z0), (x0, y1, z1), (x1, y1, z1), (x1, y1, z0)),
        '-z': ((x0, y0, z0), (x0, y1, z0), (x1, y1, z0), (x1, y0, z0)),
        '+z': ((x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)),
    }
    for f, corners in faces.items():
        if f not in skip:
            quad(*corners, m[f])


def steps(a, b, h):
    n = max(1, round((b - a) / h))
    return [a + (b - a) * i / n for i in range(n + 1)]


def tile(axis_u, axis_v, fixed, u_range, v_range, mtl_of):
    """Tiles the plane {fixed axis = value} with a GRID-sized quad mesh (shared edges, no
    T-junctions). mtl_of(u_centre, v_centre) -> material."""
    us, vs = steps(*u_range, GRID), steps(*v_range, GRID)
    fax, fval = fixed
    for i in range(len(us) - 1):
        for j in range(len(vs) - 1):
            corners = []
            for (u, v) in ((us[i], vs[j]), (us[i + 1], vs[j]), (us[i + 1], vs[j + 1]),
                           (us[i], vs[j + 1])):
                p = {axis_u: u, axis_v: v, fax: fval}
                corners.append((p['x'], p['y'], p['z']))
            quad(*corners, mtl_of(0.5 * (us[i] + us[i + 1]), 0.5 * (vs[j] + vs[j + 1])))


# --- Room shell -------------------------------------------------------------------------
def side_wall(x, y):
    window = 8.0 < x < 20.0 and 6.0 < y < 10.0 and int(x // GRID) % 2 == 0
    return 'glass' if window else 'plaster'


tile('x', 'y', ('z', 0.0), (0.0, LENGTH), (0.0, HEIGHT), side_wall)
tile('x', 'y', ('z', WIDTH), (0.0, LENGTH), (0.0, HEIGHT), side_wall)
tile('z', 'y', ('x', 0.0), (0.0, WIDTH), (0.0, HEIGHT),
     lambda z, y: 'wood_panel' if y < 5.0 else 'plaster')          # stage back wall
tile('z', 'y', ('x', LENGTH), (0.0, WIDTH), (0.0, HEIGHT),
     lambda z, y: 'curtain' if y < 4.0 else 'plaster')              # rear wall
tile('x', 'z', ('y', HEIGHT), (0.0, LENGTH), (0.0, WIDTH), lambda x, z: 'concrete')
tile('x', 'z', ('y', 0.0), (STAGE_X, LENGTH), (0.0, WIDTH), lambda x, z: 'floor')

# --- Stage: top and front (the space underneath is closed off) --------------------------
tile('x', 'z', ('y', STAGE_H), (0.0, STAGE_X), (0.0, WIDTH), lambda x, z: 'wood_stage')
tile('z', 'y', ('x', STAGE_X), (0.0, WIDTH), (0.0, STAGE_H), lambda z, y: 'wood_panel')

# --- Balcony: slab (top is floor, underside and front concrete) and parapet ------------
box(BALC_X, LENGTH, BALC_Y0, BALC_Y1, 0.0, WIDTH,
    {'-x': 'concrete', '-y': 'concrete', '+y': 'floor', '+x': '', '-z': '', '+z': ''},
    skip=('+x', '-z', '+z'))
box(BALC_X, BALC_X + 0.15, BALC_Y1, BALC_Y1 + 1.0, 0.0, WIDTH, 'wood_panel',
    skip=('-y', '-z', '+z'))

# --- Pillars under the balcony front, pilasters on the side walls ----------------------
PILLARS = [(BALC_X - 0.6, BALC_X, z - 0.25, z + 0.25) for z in (3.5, 7.5, 12.5, 16.5)]
for (x0, x1, z0, z1) in PILLARS:
    box(x0, x1, 0.0, BALC_Y0, z0, z1, 'concrete', skip=('-y', '+y'))
for x in (8.0, 12.0, 16.0, 20.0):
    box(x - 0.3, x + 0.3, 0.0, HEIGHT, 0.0, 0.4, 'concrete', skip=('-y', '+y', '-z'))
    box(x - 0.3, x + 0.3, 0.0, HEIGHT, WIDTH - 0.4, WIDTH, 'concrete', skip=('-y', '+y', '+z'))

# --- Seats ------------------------------------------------------------------------------
SEAT_W, SEAT_PITCH, ROW_PITCH = 0.5, 0.55, 0.9
BLOCKS = [(1.2, 9.25), (10.75, 18.8)]  # seat blocks across the hall; aisles between


def seat(x, y, z):
    """One seat facing the stage (-x): cushion 0.45 m deep, 0.45 m high; backrest 0.08 m
    deep, 0.9 m high. Bottom faces omitted (they rest on the floor)."""
    box(x, x + 0.45, y, y + 0.45, z, z + SEAT_W, 'seats', skip=('-y', '+x'))
    box(x + 0.45, x + 0.53, y, y + 0.9, z, z + SEAT_W, 'seats', skip=('-y',))


def overlaps_pillar(x, z):
    return any(x < px1 + 0.1 and x + 0.53 > px0 - 0.1 and z < pz1 + 0.1 and z + SEAT_W > pz0 - 0.1
               for (px0, px1, pz0, pz1) in PILLARS)


def seat_rows(x_first, x_last, y):
    count = 0
    x = x_first
    while x + 0.53 <= x_last + 1e-9:
        for (z0, z1) in BLOCKS:
            n = int((z1 - z0 + SEAT_PITCH - SEAT_W) / SEAT_PITCH)
            zs = z0 + 0.5 * ((z1 - z0) - (n * SEAT_PITCH - (SEAT_PITCH - SEAT_W)))
            for k in range(n):
                z = zs + k * SEAT_PITCH
                if not overlaps_pillar(x, z):
                    seat(x, y, z)
                    count += 1
        x += ROW_PITCH
    return count


stalls = seat_rows(8.0, LENGTH - 0.8, 0.0)
balcony = seat_rows(BALC_X + 0.9, LENGTH - 0.3, BALC_Y1)

# --- Options ----------------------------------------------------------------------------
HERE = os.path.dirname(os.path.abspath(__file__))
parser = argparse.ArgumentParser(description='Writes the dpc hall mesh (OBJ).')
parser.add_argument('out', nargs='?', default=os.path.join(HERE, 'hall.obj'), help='OBJ to write')
parser.add_argument('--subdivide', type=int, default=0, metavar='K',
                    help='split every triangle into 4^K (default 0)')
parser.add_argument('--scene', metavar='OUT.json',
                    help='also write a scene JSON (copy of hall.json) that points at OUT.obj')
args = parser.parse_args()
if args.subdivide < 0:
    parser.error('--subdivide must be >= 0')


# --- Optional subdivision: 1 triangle -> 4 by edge midpoints, K times --------------------
def midpoint(ia, ib):
    a, b = verts[ia - 1], verts[ib - 1]
    return vert(tuple(0.5 * (p + q) for p, q in zip(a, b)))


for _ in range(args.subdivide):
    for mtl, tris in groups.items():
        finer = []
        for (a, b, c) in tris:
            ab, bc, ca = midpoint(a, b), midpoint(b, c), midpoint(c, a)
            finer.extend([(a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca)])
        groups[mtl] = finer

# --- Write ------------------------------------------------------------------------------
out = args.out
ntri = sum(len(t) for t in groups.values())
with open(out, 'w') as f:
    f.write('# dpc hall, generated by scenes/generate_hall.py (do not edit by hand)\n')
    f.write(f'# {LENGTH:g} x {HEIGHT:g} x {WIDTH:g} m (x along, y up, z across); '
            f'{stalls} stall seats, {balcony} balcony seats; {len(verts)} vertices, '
            f'{ntri} triangles\n')
    if args.subdivide:
        f.write(f'# --subdivide {args.subdivide}: every triangle split into '
                f'{4 ** args.subdivide} (benchmark variant)\n')
    for (x, y, z) in verts:
        f.write(f'v {x:.4f} {y:.4f} {z:.4f}\n')
    for mtl in sorted(groups):
        f.write(f'g {mtl}\nusemtl {mtl}\n')
        for (a, b, c) in groups[mtl]:
            f.write(f'f {a} {b} {c}\n')
print(f'{out}: {len(verts)} vertices, {ntri} triangles, {stalls} + {balcony} seats',
      file=sys.stderr)

if args.scene:
    with open(os.path.join(HERE, 'hall.json')) as f:
        scene = json.load(f)
    folder = os.path.dirname(os.path.abspath(args.scene))
    scene['mesh'] = os.path.relpath(os.path.abspath(out), folder)
    for src in scene['sources']:
        src['signal'] = os.path.relpath(os.path.join(HERE, src['signal']), folder)
    scene['_comment'] = (f'Benchmark variant of scenes/hall.json written by scenes/generate_hall.py '
                         f'--subdivide {args.subdivide} ({ntri} triangles). ' + scene['_comment'])
    with open(args.scene, 'w') as f:
        json.dump(scene, f, indent=2)
        f.write('\n')
    print(f'{args.scene}: scene pointing at {scene["mesh"]}', file=sys.stderr)
