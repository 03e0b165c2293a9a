#!/usr/bin/python3
"""Generates scenes/market.obj and scenes/market.json: a covered market hall with 64 sound
sources and one walking listener, the many-source scene (docs/performance.md "Many sources").
Deterministic (no randomness; the same output every run).

The hall: 40 x 9 x 24 m (x 0..40 along, y 0..9 up, z 0..24 across): brick walls, a concrete
floor, a timber ceiling with a glazed strip along the ridge. Four rows of eight stalls (wooden
counters 3 x 1 x 1.2 m) along three aisles (z 4.5..7.5, 10.5..13.5, 16.5..19.5; the listener
walks the middle one). Sources (all looping):
  32 vendors, one behind each counter (speech, -6 dB), facing the aisle (cardioid, a talker's
     first-order approximation);
  16 shoppers standing in the aisles (speech, -12 dB);
   8 machines at the walls (percussion, -10 dB: grinders, tills);
   8 shoppers walking the aisles (speech, -12 dB, trajectories).
Material names (usemtl) are entries of materials/library.json.

Usage: generate_market.py [OUT_DIR]   (default: this script's folder)
"""
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from objfile import write_obj  # noqa: E402

LENGTH, HEIGHT, WIDTH = 40.0, 9.0, 24.0
STALL_X = [2.5 + 4.5 * i for i in range(8)]     # counter starts along x
STALL_ROWS = [(2.5, 3.5), (8.5, 9.5), (14.5, 15.5), (20.5, 21.5)]  # counter z extents
AISLES = [6.0, 12.0, 18.0]                      # aisle centre lines (z)
COUNTER_W, COUNTER_H = 3.0, 1.2

verts, index, faces = [], {}, {}


def vert(p):
    key = tuple(round(c, 4) for c in p)
    if key not in index:
        verts.append(key)
        index[key] = len(verts)
    return index[key]


def quad(a, b, c, d, mtl):
    ia, ib, ic, id_ = (vert(p) for p in (a, b, c, d))
    faces.setdefault(mtl, []).extend([(ia, ib, ic), (ia, ic, id_)])


def box(x0, x1, y0, y1, z0, z1, mtl):
    """Closed axis-aligned box (bottom face left out: it stands on the floor)."""
    quad((x0, y0, z0), (x0, y0, z1), (x0, y1, z1), (x0, y1, z0), mtl)
    quad((x1, y0, z0), (x1, y1, z0), (x1, y1, z1), (x1, y0, z1), mtl)
    quad((x0, y1, z0), (x0, y1, z1), (x1, y1, z1), (x1, y1, z0), mtl)
    quad((x0, y0, z0), (x0, y1, z0), (x1, y1, z0), (x1, y0, z0), mtl)
    quad((x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1), mtl)


def hall():
    """The shell, facing inward; the ceiling has a glazed strip z 9..15."""
    L, H, W = LENGTH, HEIGHT, WIDTH
    quad((0, 0, 0), (L, 0, 0), (L, 0, W), (0, 0, W), "concrete_floor")
    quad((0, H, 0), (0, H, 9), (L, H, 9), (L, H, 0), "wood_16mm_on_studs")
    quad((0, H, 9), (0, H, 15), (L, H, 15), (L, H, 9), "glass_window")
    quad((0, H, 15), (0, H, W), (L, H, W), (L, H, 15), "wood_16mm_on_studs")
    quad((0, 0, 0), (0, H, 0), (L, H, 0), (L, 0, 0), "brickwork_10mm_pointing")
    quad((0, 0, W), (L, 0, W), (L, H, W), (0, H, W), "brickwork_10mm_pointing")
    quad((0, 0, 0), (0, 0, W), (0, H, W), (0, H, 0), "brickwork_10mm_pointing")
    quad((L, 0, 0), (L, H, 0), (L, H, W), (L, 0, W), "brickwork_10mm_pointing")


def stalls():
    for z0, z1 in STALL_ROWS:
        for x0 in STALL_X:
            box(x0, x0 + COUNTER_W, 0.0, COUNTER_H, z0, z1, "wooden_lining_12mm")


def rotation_facing(dz):
    """Quaternion [x, y, z, w] turning +x toward +z (dz > 0) or -z (dz < 0) about +y."""
    s = 0.7071067811865476
    return [0.0, -s, 0.0, s] if dz > 0 else [0.0, s, 0.0, s]


def source(name, pos, signal, gain_db, **extra):
    s = {"name": name, "position": [round(c, 3) for c in pos], "signal": signal,
         "gain_db": gain_db, "loop": True}
    s.update(extra)
    return s


def vendors():
    out = []
    for r, (z0, z1) in enumerate(STALL_ROWS):
        # Rows 0 and 2 serve the aisle on their +z side, rows 1 and 3 the one on their -z side.
        toward = 1.0 if r % 2 == 0 else -1.0
        z = (z0 - 0.7) if toward > 0 else (z1 + 0.7)
        for i, x0 in enumerate(STALL_X):
            out.append(source(f"vendor {r}.{i}", (x0 + 1.5, 1.6, z), "signals/speech.wav", -6,
                              directivity="cardioid", rotation=rotation_facing(toward)))
    return out


def shoppers():
    out = []
    for a, z in enumerate(AISLES):
        for i in range(6 if a != 1 else 4):
            x = 4.0 + 6.5 * i + 1.3 * a
            out.append(source(f"shopper {a}.{i}", (x, 1.5, z + (0.8 if i % 2 else -0.8)),
                              "signals/speech.wav", -12))
    return out


def machines():
    out = []
    for i in range(4):
        x = 5.0 + 10.0 * i
        out.append(source(f"machine north {i}", (x, 1.0, 0.8), "signals/percussion.wav", -10))
        # 0.8 m from the south wall, and from the east wall for the last (not on it).
        out.append(source(f"machine south {i}", (min(x + 5.0, LENGTH - 0.8), 1.0, WIDTH - 0.8),
                          "signals/percussion.wav", -10))
    return out


def walkers():
    out = []
    for i in range(8):
        z = AISLES[i % 3] + (0.6 if i % 2 else -0.6)
        x0, x1 = (3.0, 37.0) if i % 2 == 0 else (37.0, 3.0)
        t = 34.0 / 1.3  # 1.3 m/s
        traj = [{"t": 0.0, "position": [x0, 1.5, z]},
                {"t": round(t, 3), "position": [x1, 1.5, z]},
                {"t": round(2 * t, 3), "position": [x0, 1.5, z]}]
        s = source(f"walker {i}", (x0, 1.5, z), "signals/speech.wav", -12,
                   trajectory=traj, trajectory_loop=True)
        s["position"] = traj[0]["position"]
        s["_comment"] = f"walks aisle z = {z:g} at 1.3 m/s, end to end and back"
        out.append(s)
    return out


def listener():
    z = AISLES[1]
    return {
        "_comment": "Ear height 1.6 m, radius 0.5 m; walks the middle aisle and back at 1.2 m/s.",
        "position": [3.0, 1.6, z], "radius": 0.5,
        "trajectory": [{"t": 0.0, "position": [3.0, 1.6, z]},
                       {"t": 28.333, "position": [37.0, 1.6, z]},
                       {"t": 56.667, "position": [3.0, 1.6, z]}],
        "loop": True}


def scene(sources):
    return {
        "_comment": "Covered market, 40 x 9 x 24 m, 32 stalls, 64 looping sources (vendors, "
                    "shoppers, machines, walkers) and a walking listener: the many-source "
                    "scene (scenes/generate_market.py writes market.obj and this file; "
                    "docs/performance.md \"Many sources\"). Traced from the listener "
                    "(tracing auto). Materials: materials/library.json.",
        "mesh": "market.obj",
        "materials": {
            "concrete_floor": "concrete_floor",
            "wood_16mm_on_studs": {"library": "wood_16mm_on_studs", "scattering": 0.3},
            "glass_window": "glass_window",
            "brickwork_10mm_pointing": {"library": "brickwork_10mm_pointing", "scattering": 0.4},
            "wooden_lining_12mm": {"library": "wooden_lining_12mm", "scattering": 0.5},
        },
        "sources": sources,
        "listener": listener(),
        "propagation": {"rays_per_frame": 4096, "max_order": 200, "exact_order": 3,
                        "cache_tau": 1.0, "frame_rate": 15, "ir_length": 2.0, "seed": 1,
                        "tracing": "auto"},
        "audio": {"sample_rate": 48000, "block_size": 512},
    }


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.abspath(__file__))
    hall()
    stalls()
    header = ("# Covered market hall, 40 x 9 x 24 m, 32 stall counters "
              "(scenes/generate_market.py)\n")
    write_obj(os.path.join(out, "market.obj"), header, verts, sorted(faces.items()))
    sources = vendors() + shoppers() + machines() + walkers()
    assert len(sources) == 64, len(sources)
    with open(os.path.join(out, "market.json"), "w") as f:
        json.dump(scene(sources), f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
