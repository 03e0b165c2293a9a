"""dpc.Engine as a user steps it (run by ctest's python:pytest), each result checked against
physics computed here, not by dpc:

- 50 steps of a listener walking away from the shoebox's talker: the frame count is the
  number of steps, every frame's energy response differs from the one before, and each frame's
  direct sound has the energy 1 / (4 pi r^2) of the listener's distance r that frame, in the
  bin of r / c, and is the IR's Dirac at the sample of r / c;
- two sources at different distances: each source's impulse response has its direct sound at
  its own distance / c;
- a teleport drops the cache (the late response changes, the direct sound stays), and a door
  shut with set_object_pose takes the high bands of the direct sound through it, which
  reopening it restores;
- every property of dpc.Engine reads, with the scene's values.
The poses are set after the tenth frame too: an engine that stops following them (a frozen
frame) fails every check.
"""
import json
import math
import os

import numpy as np
import pytest

import dpc

SOURCE_DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
SCENES = os.path.join(SOURCE_DIR, "scenes")
SHOEBOX = os.path.join(SCENES, "shoebox.json")
TWO_ROOMS = os.path.join(SCENES, "two_rooms.json")
BIN_S = 1e-3  # the energy response's bins (docs/python.md)


def speed_of_sound(scene):
    """c of the scene's air temperature (ideal gas: 331.3 m/s at 0 degrees C), m/s."""
    t = json.load(open(scene))["propagation"].get("temperature", 20.0)
    return 331.3 * math.sqrt(1.0 + t / 273.15)


def direct_bin(distance, c):
    return int(distance / c / BIN_S)


def direct_sound_peak(ir, distance, c, fs):
    """The sample of the IR's largest magnitude up to (distance + 0.5 m) / c: the direct sound
    (a band-filtered Dirac, zero-phase, centred on its delay) before any reflection."""
    window = ir[:int((distance + 0.5) / c * fs)]
    peak = int(np.argmax(np.abs(window)))
    return peak, float(window[peak])


def test_fifty_steps_follow_a_walking_listener():
    scene = json.load(open(SHOEBOX))
    talker = np.array(scene["sources"][0]["position"])  # (2, 1.6, 3.5)
    c = speed_of_sound(SHOEBOX)
    e = dpc.Engine(SHOEBOX, rays_per_frame=256)
    fs = e.sample_rate
    previous = None
    for step in range(50):
        # From 1 m to 6.4 m from the talker along +x, 0.11 m a frame (1.65 m/s at the scene's
        # 15 frames/s); the listener sphere (0.5 m) stays 1.1 m or more from every wall.
        listener = talker + np.array([1.0 + 0.11 * step, 0.0, 0.0])
        e.set_listener_pose(0, listener, yaw_degrees=180.0)
        e.step()
        assert e.frames == step + 1
        er = e.energy_response(0)  # 8 bands x 1 ms bins, 1/m^2
        r = float(np.linalg.norm(listener - talker))
        free_field = 1.0 / (4.0 * math.pi * r * r)
        # The direct sound, 1/(4 pi r^2), is in the bin of r / c in full: at 63 Hz air takes
        # 1.2e-4 dB/m (ISO 9613-1), under 1e-3 of it within 7 m. The bin may hold more: the
        # path cache averages its paths' delays over its window (tau = 1 s), so while the
        # listener walks away cached reflections arrive early (docs/dynamic.md).
        assert er[0, direct_bin(r, c)] > (1.0 - 1e-3) * free_field, (step, r)
        # In the IR: a Dirac at the sample of r / c (rounded), of amplitude sqrt(1/(4 pi r^2))
        # less air absorption averaged over the bands (at most 10 % within 7 m: 8 kHz loses
        # 0.1 dB/m), give or take the noise of the diffuse part on that sample (a few %).
        peak, amplitude = direct_sound_peak(e.impulse_response(0)[0], r, c, fs)
        assert abs(peak - r / c * fs) <= 1.0, (step, peak, r / c * fs)
        assert 0.9 < amplitude / math.sqrt(free_field) < 1.1, (step, amplitude)
        if previous is not None:
            assert not np.array_equal(er, previous), step
        previous = er


def box_with_two_sources(sources, listener):
    """A 12 x 3 x 4 m box (x, y up, z), wound inward, one material."""
    v = np.array([(x, y, z) for x in (0, 12) for y in (0, 3) for z in (0, 4)], dtype=np.float32)
    quads = [(0, 4, 6, 2), (1, 3, 7, 5), (0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3)]
    tris = np.array([t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))], np.uint32)
    return dpc.Engine.from_arrays(v, tris, np.zeros(len(tris), np.uint32),
                                  np.full((1, 8), 0.2, np.float32), np.array([0.3], np.float32),
                                  sources=sources, listener=listener, rays_per_frame=500)


def test_each_source_has_its_own_impulse_response():
    listener = np.array([10.0, 1.5, 2.0])
    sources = np.array([[2.0, 1.5, 2.0], [7.0, 1.5, 2.0]])  # 8 m and 3 m from the listener
    e = box_with_two_sources(sources, listener)
    c = 331.3 * math.sqrt(1.0 + 20.0 / 273.15)  # from_arrays: the scene file's default, 20 C
    for _ in range(12):
        e.step()
    peaks = []
    for s, position in enumerate(sources):
        r = float(np.linalg.norm(position - listener))
        peak, amplitude = direct_sound_peak(e.impulse_response(s)[0], r, c, e.sample_rate)
        assert abs(peak - r / c * e.sample_rate) <= 1.0, (s, peak, r / c * e.sample_rate)
        assert 0.9 < amplitude * math.sqrt(4.0 * math.pi) * r < 1.1, (s, amplitude)
        peaks.append(peak)
    assert peaks[0] != peaks[1]


def stepped_shoebox(frames, teleport_at=None):
    e = dpc.Engine(SHOEBOX, rays_per_frame=256)
    e.set_listener_pose(0, [7.0, 1.6, 3.5])
    for frame in range(frames):
        if frame == teleport_at:
            e.teleport_listener(0)
        e.step()
    return e.energy_response(0)


def test_teleport_drops_the_cache_and_keeps_the_direct_sound():
    # Identical engines; one is told at frame 12 that its listener jumped. A frame's rays
    # depend on the seed and frame number only, so the difference is the dropped cache.
    kept, dropped = stepped_shoebox(13), stepped_shoebox(13, teleport_at=12)
    k = direct_bin(5.0, speed_of_sound(SHOEBOX))  # talker (2, 1.6, 3.5), 5 m away
    assert np.array_equal(kept[:, :k + 1], dropped[:, :k + 1])  # the analytic direct sound
    assert not np.array_equal(kept[:, k + 1:], dropped[:, k + 1:])


def door_response(e, rotation, frames):
    e.set_object_pose(0, [6.0, 0.0, 3.5], rotation)  # the door's hinge (scenes/two_rooms.json)
    for _ in range(frames):
        e.step()
    return e.energy_response(0)


def test_shutting_the_door_takes_the_direct_sound():
    e = dpc.Engine(TWO_ROOMS, rays_per_frame=256)
    assert e.object_count == 1
    # The talker in room A and the listener in room B, in line through the doorway (z 3.5 ..
    # 4.5, below 2.1 m), 6 m apart.
    e.set_source_position(0, [3.0, 1.6, 4.0])
    e.set_listener_pose(0, [9.0, 1.6, 4.0], yaw_degrees=180.0)
    k = direct_bin(6.0, speed_of_sound(TWO_ROOMS))
    opened = [0.0, 0.70710678, 0.0, 0.70710678]  # turned 90 degrees into room B
    open_er = door_response(e, opened, 11)
    shut_er = door_response(e, [0.0, 0.0, 0.0, 1.0], 1)
    reopened = door_response(e, opened, 1)
    change_db = 10 * np.log10(shut_er[:, k] / open_er[:, k])
    # Shut, the direct sound's bin holds the sound through the leaf (R 18 .. 36 dB,
    # materials/library.json) and the edge paths through its 1 cm clearance
    # (docs/dynamic.md), both falling with frequency: every band changes, and from 2 kHz up the
    # leaf takes more than 6 dB. The direct sound and the edge paths are analytic: reopened,
    # the bin is the open door's again.
    assert np.all(np.abs(change_db) > 1.0), change_db
    assert np.all(change_db[5:] < -6.0), change_db
    assert np.array_equal(reopened[:, k], open_er[:, k])


def test_every_property_reads_the_scene(tmp_path):
    e = dpc.Engine(TWO_ROOMS, rays_per_frame=64)
    assert (e.sample_rate, e.block_size) == (48000, 512)  # docs/scene-format.md's defaults
    assert (e.source_count, e.listener_count, e.object_count) == (2, 2, 1)
    assert (e.output_channels, e.ir_channels) == (1, 1)  # "mono", the default output
    assert e.frames == 0
    e.step()
    assert e.frames == 1
    assert e.impulse_response(1).shape[0] == e.ir_channels
    # Another rate, block and output: (order + 1)^2 AmbiX IR channels decoded to two ears.
    scene = json.load(open(SHOEBOX))
    scene["mesh"] = os.path.join(SCENES, scene["mesh"])
    scene["sources"][0]["signal"] = os.path.join(SCENES, scene["sources"][0]["signal"])
    scene["audio"] = {"sample_rate": 44100, "block_size": 256, "output": "ambisonic_binaural",
                      "ambisonic_order": 2}
    (tmp_path / "scene.json").write_text(json.dumps(scene))
    e = dpc.Engine(str(tmp_path / "scene.json"), rays_per_frame=64)
    assert (e.sample_rate, e.block_size) == (44100, 256)
    assert (e.source_count, e.listener_count, e.object_count) == (1, 1, 0)
    assert (e.output_channels, e.ir_channels) == (2, 9)
    e.step()
    assert e.impulse_response(0).shape[0] == 9
