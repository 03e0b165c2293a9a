#!/usr/bin/env python3
"""Bad-input suite for dpc-demo (docs/scene-format.md, "Limits").

Each case copies the shoebox scene into a fresh folder, damages one thing, runs dpc-demo under a
time limit (timeout) and an address-space limit (RLIMIT_AS) and asserts: exit status 1 (no
signal), exactly one "dpc-demo: ..." line on stderr containing the expected file/field text, no
new file in the folder, every existing file byte-identical afterwards.

  run.py DPC_DEMO SCENES_DIR --list      print the case names
  run.py DPC_DEMO SCENES_DIR CASE...     run the named cases (all when none given)
"""
import hashlib, json, math, os, re, resource, shutil, signal, subprocess, sys, tempfile

TIME_LIMIT_S = 60
MEMORY_LIMIT_BYTES = 4 << 30


import setups
from setups import (
    scene_with, without, write, obj_with, nothing, write_text, two_listeners, bake_file,
    truncate_half, read_only, read_only_folder, open_to_nobody, fifo, symlink, mkdir, sparse, float_wav, gltf_level,
    gltf_set, gltf_door, no_edit, gltf_nan_vertex, gltf_door_on_node_9, steps,
    gltf_index_out_of_range, gltf_deep_nesting, gltf_node_chain, glb_bytes, fbx_level)


OFF = ["shoebox.json", "--offline", "out.wav", "--duration", "0.2", "--rays", "64"]

# name: (setup, extra args or full args, expected substring of the error line)
CASES = {
    # Finding 1: deep nesting.
    "deep_json_array": (write("shoebox.json", "[" * 100000 + "]" * 100000), OFF, "nested deeper"),
    "deep_json_object": (write("shoebox.json", '{"a":' * 50000 + "1" + "}" * 50000), OFF, "nested deeper"),
    "deep_json_unclosed": (write("shoebox.json", "[" * 100000), OFF, "nested deeper"),
    # Finding 2: huge coordinates.
    "source_1e20": (scene_with(**{"sources.0.position": [1e20, 1.6, 3.5]}), OFF, "sources[0].position[0]"),
    "source_neg_1e7": (scene_with(**{"sources.0.position": [2, -1e7, 3.5]}), OFF, "sources[0].position[1]"),
    "listener_1e30": (scene_with(**{"listener.position": [1e30, 1.6, 1.5]}), OFF, "listener.position[0]"),
    "keyframe_1e9": (scene_with(**{"listener.trajectory.1.position": [8.5, 1.6, 1e9]}), OFF, "listener.trajectory[1].position[2]"),
    # The wave band (scene key "wave", docs/wave.md).
    "wave_crossover_above_max": (scene_with(wave={"enabled": True, "max_frequency": 200, "crossover_hz": 300}), OFF, "shoebox.json: wave.crossover_hz: 300 Hz must lie below wave.max_frequency"),
    "wave_grid_too_coarse": (scene_with(wave={"grid_spacing": 0.5}), OFF, "shoebox.json: wave.grid_spacing: 0.5 m is too coarse"),
    "wave_max_frequency_5000": (scene_with(wave={"max_frequency": 5000}), OFF, "shoebox.json: wave.max_frequency: 5000 is outside [20, 4000] Hz"),
    "wave_key_typo": (scene_with(wave={"enable": True}), OFF, "wave"),
    "wave_enabled_not_bool": (scene_with(wave={"enabled": "yes"}), OFF, "wave.enabled"),
    "wave_with_moving_listener": (scene_with(wave={"enabled": True, "max_frequency": 100}), OFF, "shoebox.json: wave.enabled: the wave band is simulated for one pose of the scene, and listeners[0].trajectory moves"),
    "wave_source_outside_room": (scene_with(wave={"enabled": True, "max_frequency": 100}, listener={"position": [8.5, 1.6, 1.5]}, **{"sources.0.position": [-3, 1.6, 3.5]}), OFF, "sources[0].position: lies in no air"),
    # Finding 3: outputs naming inputs or non-regular files.
    "offline_is_scene": (nothing, ["shoebox.json", "--offline", "shoebox.json"], "--offline"),
    "offline_is_mesh": (nothing, ["shoebox.json", "--offline", "shoebox.obj"], "the mesh"),
    "offline_is_signal": (nothing, ["shoebox.json", "--offline", "signals/speech.wav"], "a dry signal"),
    "offline_symlink_to_scene": (symlink("shoebox.json", "link.wav"), ["shoebox.json", "--offline", "link.wav"], "the scene file"),
    "offline_dotdot_scene": (nothing, ["shoebox.json", "--offline", "signals/../shoebox.json"], "the scene file"),
    "offline_dev_null": (nothing, ["shoebox.json", "--offline", "/dev/null"], "not a regular file"),
    "offline_directory": (mkdir("adir"), ["shoebox.json", "--offline", "adir"], "not a regular file"),
    "offline_fifo": (fifo("out.fifo"), ["shoebox.json", "--offline", "out.fifo"], "not a regular file"),
    "offline_missing_folder": (nothing, ["shoebox.json", "--offline", "missing/out.wav"], "does not exist"),
    "ir_out_same_as_offline": (nothing, ["shoebox.json", "--offline", "o.wav", "--ir-out", "./o.wav"], "--ir-out"),
    "ir_out_is_scene": (nothing, ["shoebox.json", "--offline", "o.wav", "--ir-out", "shoebox.json"], "--ir-out"),
    "ir_out_missing_folder": (nothing, ["shoebox.json", "--offline", "o.wav", "--ir-out", "nope/ir.wav"], "--ir-out"),
    # The --bake file and a --output layout:FILE.json are inputs too: --offline replaced them
    # with the render (exit status 0).
    "offline_is_bake": (bake_file(), ["shoebox.json", "--offline", "bake.h5", "--bake", "bake.h5"], "--offline: 'bake.h5' is the bake; refusing to overwrite it"),
    "ir_out_is_bake": (bake_file(), OFF + ["--bake", "bake.h5", "--ir-out", "./bake.h5"], "--ir-out: './bake.h5' is the bake; refusing to overwrite it"),
    "offline_is_layout": (write("lay.json", '{"speakers": [{"name": "A", "azimuth": 30}, {"name": "B", "azimuth": -30}]}'), ["shoebox.json", "--offline", "lay.json", "--output", "layout:lay.json"], "--offline: 'lay.json' is the loudspeaker layout; refusing to overwrite it"),
    "er_out_is_layout": (write("lay.json", '{"speakers": [{"name": "A", "azimuth": 30}, {"name": "B", "azimuth": -30}]}'), OFF + ["--output", "layout:lay.json", "--er-out", "lay.json"], "--er-out: 'lay.json' is the loudspeaker layout; refusing to overwrite it"),
    "record_is_signal": (nothing, ["shoebox.json", "--record", "signals/speech.wav", "--duration", "1"], "--record"),
    "record_missing_folder": (nothing, ["shoebox.json", "--record", "missing/r.wav", "--duration", "1"], "--record"),
    "stats_is_scene": (nothing, ["shoebox.json", "--stats", "shoebox.json", "--duration", "1"], "--stats"),
    "stats_missing_folder": (nothing, ["shoebox.json", "--stats", "missing/s.json", "--duration", "1"], "--stats"),
    "stats_with_offline": (nothing, ["shoebox.json", "--offline", "out.wav", "--stats", "s.json"], "--stats"),
    "latency_target_zero": (nothing, ["shoebox.json", "--latency-target-ms", "0", "--duration", "1"], "--latency-target-ms"),
    "latency_target_nan": (nothing, ["shoebox.json", "--latency-target-ms", "nan", "--duration", "1"], "--latency-target-ms"),
    "latency_target_with_offline": (nothing, ["shoebox.json", "--offline", "out.wav", "--latency-target-ms", "40"], "--latency-target-ms"),
    "swap_spread_negative": (nothing, ["shoebox.json", "--ir-swap-spread-ms", "-1", "--duration", "1"], "--ir-swap-spread-ms"),
    "swap_spread_over_max": (nothing, ["shoebox.json", "--ir-swap-spread-ms", "100.5", "--duration", "1"], "--ir-swap-spread-ms"),
    "swap_spread_nan": (nothing, ["shoebox.json", "--ir-swap-spread-ms", "nan", "--duration", "1"], "--ir-swap-spread-ms"),
    "swap_spread_with_offline": (nothing, ["shoebox.json", "--offline", "out.wav", "--ir-swap-spread-ms", "20"], "--ir-swap-spread-ms"),
    "reconnect_negative": (nothing, ["shoebox.json", "--reconnect", "-1", "--duration", "1"], "--reconnect"),
    "reconnect_over_max": (nothing, ["shoebox.json", "--reconnect", "3600.5", "--duration", "1"], "--reconnect"),
    "reconnect_nan": (nothing, ["shoebox.json", "--reconnect", "nan", "--duration", "1"], "--reconnect"),
    "reconnect_with_offline": (nothing, ["shoebox.json", "--offline", "out.wav", "--reconnect", "5"], "--reconnect"),
    "offline_is_hrtf": (lambda d: shutil.copy("/usr/share/libmysofa/default.sofa", os.path.join(d, "h.sofa")) if os.path.exists("/usr/share/libmysofa/default.sofa") else open(os.path.join(d, "h.sofa"), "w").write("x"),
                        ["shoebox.json", "--offline", "h.sofa", "--hrtf", "h.sofa"], "--"),
    # Finding 4 and 5: non-regular or huge inputs.
    "scene_fifo": (fifo("f.json"), ["f.json", "--offline", "out.wav"], "not a regular file"),
    "scene_dev_zero": (nothing, ["/dev/zero", "--offline", "out.wav"], "not a regular file"),
    "scene_dev_urandom": (nothing, ["/dev/urandom", "--offline", "out.wav"], "not a regular file"),
    "scene_directory": (mkdir("s.json"), ["s.json", "--offline", "out.wav"], "is a directory"),
    "scene_missing": (nothing, ["none.json", "--offline", "out.wav"], "not found"),
    "scene_huge_sparse": (sparse("big.json", 1 << 33), ["big.json", "--offline", "out.wav"], "MiB"),
    "mesh_dev_zero": (scene_with(mesh="/dev/zero"), OFF, "mesh"),
    "mesh_dev_urandom": (scene_with(mesh="/dev/urandom"), OFF, "mesh"),
    "mesh_fifo": (lambda d: (fifo("m.obj")(d), scene_with(mesh="m.obj")(d)), OFF, "mesh"),
    "mesh_directory": (lambda d: (mkdir("m.obj")(d), scene_with(mesh="m.obj")(d)), OFF, "mesh"),
    "mesh_huge_sparse": (lambda d: (sparse("m.obj", 1 << 34)(d), scene_with(mesh="m.obj")(d)), OFF, "mesh"),
    "signal_dev_zero": (scene_with(**{"sources.0.signal": "/dev/zero"}), OFF, '/dev/zero" is not a regular file'),
    "signal_fifo": (lambda d: (fifo("s.wav")(d), scene_with(**{"sources.0.signal": "s.wav"})(d)), OFF, "s.wav"),
    "signal_directory": (scene_with(**{"sources.0.signal": "signals"}), OFF, "signals"),
    "signal_huge_sparse": (lambda d: (sparse("s.wav", 1 << 35)(d), scene_with(**{"sources.0.signal": "s.wav"})(d)), OFF, "s.wav"),
    # A WAV cut short of its data chunk: libsndfile reads what is there, and the render used the
    # shorter signal without a word.
    "signal_truncated": (steps(float_wav("cut.wav", 48000, [0.1] * 4800), lambda d: truncate_half(os.path.join(d, "cut.wav"))), OFF,
                         "sources[0].signal: cut.wav: cannot read: truncated: its data chunk lacks the last 9622 bytes"),
    # A fmt chunk with rate 0: libsndfile said "Internal error : SF_INFO struct incomplete."
    "signal_rate_zero": (float_wav("z.wav", 0, [0.1] * 100), OFF,
                         "sources[0].signal: z.wav: cannot read: its fmt chunk declares a sample rate of 0 Hz"),
    "signal_not_wav": (lambda d: (write("s.wav", "not audio")(d), scene_with(**{"sources.0.signal": "s.wav"})(d)), OFF, "s.wav"),
    "signal_nan": (float_wav("n.wav", 48000, [0.1] * 100 + [float("nan")] + [0.1] * 100), OFF, "n.wav: sample 100 (0 = first) of channel 1 is not finite"),
    "signal_inf": (float_wav("n.wav", 48000, [0.1] * 10 + [float("inf")]), OFF, "sources[0].signal: n.wav"),
    "signal_100hz": (float_wav("lo.wav", 100, [0.1] * 100), OFF, "sample rate 100 Hz is outside"),
    "signal_2mhz": (float_wav("hi.wav", 2000000, [0.1] * 1000), OFF, "sample rate 2000000 Hz"),
    "hrtf_dev_zero": (nothing, OFF + ["--hrtf", "/dev/zero"], "--hrtf"),
    "hrtf_missing": (nothing, OFF + ["--hrtf", "none.sofa"], "--hrtf"),
    # Finding 7: integers out of range.
    "rays_3e9": (nothing, OFF + ["--rays", "3000000000"], "--rays"),
    "rays_2p32_plus_1": (nothing, OFF + ["--rays", "4294967297"], "--rays"),
    "rays_zero": (nothing, OFF + ["--rays", "0"], "--rays"),
    "rays_negative": (nothing, OFF + ["--rays", "-5"], "--rays"),
    "max_order_huge": (nothing, OFF + ["--max-order", "1000000"], "--max-order"),
    "max_order_negative": (nothing, OFF + ["--max-order", "-1"], "--max-order"),
    "threads_huge": (nothing, OFF + ["--threads", "99999"], "--threads"),
    "seed_negative": (nothing, OFF + ["--seed", "-1"], "--seed"),
    "seed_text": (nothing, OFF + ["--seed", "abc"], "--seed"),
    "seed_2_pow_64": (nothing, OFF + ["--seed", "18446744073709551616"], "is not a whole number"),
    "rays_2_pow_63": (nothing, OFF + ["--rays", "9223372036854775808"], "is not a whole number"),
    "offline_empty": (nothing, ["shoebox.json", "--offline", "", "--duration", "1"], "dpc-demo: command line: --offline: is empty"),
    "block_size_huge": (nothing, ["shoebox.json", "--block-size", "100000", "--duration", "1"], "--block-size"),
    # --block-size is the offline renderer's block too: range-checked there as well.
    "block_size_offline_1": (nothing, OFF + ["--block-size", "1"], "--block-size: 1 is outside [16, 8192] samples"),
    "block_size_offline_huge": (nothing, OFF + ["--block-size", "100000"], "--block-size: 100000 is outside"),
    # An empty value is refused for every option that takes one (CLI11 read an empty number as
    # "not given", an empty path as "no such output").
    **{f"empty_{flag[2:].replace('-', '_')}": (nothing, OFF + [flag, ""], f"dpc-demo: command line: {flag}: is empty")
       for flag in ["--duration", "--ir-out", "--er-out", "--listener", "--hrtf", "--output", "--bake",
                    "--seed", "--rays", "--tau", "--gain-db", "--block-size", "--estimator",
                    "--device", "--record", "--stats", "--binaural-decoder", "--ambisonic-order"]},
    "empty_scene": (nothing, ["", "--offline", "out.wav"], "dpc-demo: command line: scene: is empty"),
    "empty_duration_equals": (nothing, ["shoebox.json", "--offline", "out.wav", "--duration="], "--duration"),
    "scene_rays_1e10": (scene_with(**{"propagation.rays_per_frame": 10000000000}), OFF[:-2], "rays_per_frame"),
    # The scene file's own bad value is the file's, also where a flag overrides it (it was
    # blamed on the flag the user had set correctly).
    "scene_rays_zero_beside_flag": (scene_with(**{"propagation.rays_per_frame": 0}), OFF, "shoebox.json: propagation.rays_per_frame"),
    "scene_max_order_negative_beside_flag": (scene_with(**{"propagation.max_order": -1}), OFF + ["--max-order", "5"], "shoebox.json: propagation.max_order"),
    "scene_max_order_huge": (scene_with(**{"propagation.max_order": 1000000}), OFF, "max_order"),
    "obj_index_huge": (obj_with("f 1 2 99999999999"), OFF, "99999999999"),
    "obj_vertex_1e20": (obj_with("v 1e20 0 0"), OFF, "shoebox.obj"),
    # Face tokens tinyobjloader would read otherwise than written ("2.5" and "2x" as 2, "a" and
    # "#" as 0): the first two rendered without a word, the others blamed "vertex index 0".
    "obj_face_index_fraction": (obj_with("f 1 2.5 5"), OFF, 'shoebox.obj: face 13 (line 29): "2.5" is not a vertex reference'),
    "obj_face_index_trailing_text": (obj_with("f 1 2x 5"), OFF, 'shoebox.obj: face 13 (line 29): "2x" is not a vertex reference'),
    "obj_face_index_word": (obj_with("f 1 a 5"), OFF, 'shoebox.obj: face 13 (line 29): "a" is not a vertex reference'),
    "obj_face_trailing_comment": (obj_with("f 1 2 5 # c"), OFF, 'shoebox.obj: face 13 (line 29): "#" is not a vertex reference'),
    # A bare "f" (tinyobjloader calls no callback for it): a hole in the mesh, exit 0 before.
    "obj_face_empty": (obj_with("f"), OFF, 'shoebox.obj: face 13 (line 29): a face needs at least 3 vertices'),
    "obj_face_blank": (obj_with("f   "), OFF, 'shoebox.obj: face 13 (line 29): a face needs at least 3 vertices'),
    "obj_face_four_parts": (obj_with("f 1/1/1/1 2 5"), OFF, 'shoebox.obj: face 13 (line 29): "1/1/1/1" is not a vertex reference'),
    # Finding 9: unclear messages.
    "tau_inf": (nothing, OFF + ["--tau", "inf"], "--tau"),
    "tau_nan": (nothing, OFF + ["--tau", "nan"], "--tau"),
    "duration_1e9": (nothing, ["shoebox.json", "--offline", "out.wav", "--duration=1e9"], "--duration"),
    "duration_inf": (nothing, ["shoebox.json", "--offline", "out.wav", "--duration=inf"], "--duration"),
    "duration_zero": (nothing, ["shoebox.json", "--offline", "out.wav", "--duration=0"], "--duration"),
    "duration_negative": (nothing, ["shoebox.json", "--offline", "out.wav", "--duration=-1"], "--duration"),
    "gain_nan": (nothing, OFF + ["--gain-db", "nan"], "--gain-db"),
    "gain_inf": (nothing, OFF + ["--gain-db", "inf"], "--gain-db"),
    "gain_huge": (nothing, OFF + ["--gain-db", "1000"], "--gain-db"),
    "typo_flag": (nothing, OFF + ["--raus", "5"], "did you mean --rays"),
    "typo_flag_offline": (nothing, ["shoebox.json", "--ofline", "out.wav"], "did you mean --offline"),
    "unknown_flag": (nothing, OFF + ["--zzzzzzzz"], "command line"),
    "estimator_bad": (nothing, OFF + ["--estimator", "magic"], "--estimator"),
    "weighting_bad": (nothing, OFF + ["--dpc-weighting", "x"], "--dpc-weighting"),
    "output_bad": (nothing, OFF + ["--output", "quad"], "--output"),
    "sofa_offline_audio": (nothing, ["shoebox.json", "--offline", "out.sofa", "--duration", "1"], "--offline"),
    "sofa_record_audio": (nothing, ["shoebox.json", "--record", "out.sofa", "--duration", "1"], "--record"),
    "sofa_ir_out_live": (nothing, ["shoebox.json", "--ir-out", "ir.sofa", "--duration", "1"], "--ir-out"),
    "binaural_decoder_unknown": (nothing, OFF + ["--output", "ambisonic_binaural", "--binaural-decoder", "magic"], "--binaural-decoder"),
    "binaural_decoder_scene": (scene_with(**{"audio.output": "ambisonic_binaural", "audio.binaural_decoder": "magic"}), OFF, "audio.binaural_decoder"),
    "layout_unknown": (nothing, OFF + ["--output", "layout:quad"], "--output"),
    "layout_duplicate_angle": (write("lay.json", '{"speakers": [{"name": "A", "azimuth": 30}, {"name": "B", "azimuth": 30.4}, {"name": "C", "azimuth": -30}]}'), OFF + ["--output", "layout:lay.json"], "lay.json: speakers[1]"),
    "layout_duplicate_name": (write("lay.json", '{"speakers": [{"name": "A", "azimuth": 30}, {"name": "A", "azimuth": -30}]}'), OFF + ["--output", "layout:lay.json"], "lay.json: speakers[1].name"),
    "layout_nan_angle": (write("lay.json", '{"speakers": [{"name": "A", "azimuth": NaN}, {"name": "B", "azimuth": -30}]}'), OFF + ["--output", "layout:lay.json"], "lay.json"),
    "layout_angle_range": (write("lay.json", '{"speakers": [{"name": "A", "azimuth": 30, "elevation": 91}, {"name": "B", "azimuth": -30}]}'), OFF + ["--output", "layout:lay.json"], "lay.json: speakers[0].elevation"),
    "layout_lfe_only": (write("lay.json", '{"speakers": [{"name": "A", "azimuth": 30}, {"name": "LFE", "lfe": true}]}'), OFF + ["--output", "layout:lay.json"], "lay.json: speakers"),
    "layout_distance_negative": (write("lay.json", '{"speakers": [{"name": "A", "azimuth": 30, "distance": -2}, {"name": "B", "azimuth": -30, "distance": 2}]}'), OFF + ["--output", "layout:lay.json"], "lay.json: speakers[0].distance"),
    "layout_distance_missing": (write("lay.json", '{"speakers": [{"name": "A", "azimuth": 30, "distance": 2}, {"name": "B", "azimuth": -30}]}'), OFF + ["--output", "layout:lay.json"], "lay.json: speakers[1].distance"),
    "layout_distance_nan": (write("lay.json", '{"speakers": [{"name": "A", "azimuth": 30, "distance": NaN}, {"name": "B", "azimuth": -30, "distance": 2}]}'), OFF + ["--output", "layout:lay.json"], "lay.json"),
    "layout_missing_file": (nothing, OFF + ["--output", "layout:none.json"], "none.json"),
    "ambisonic_order_0": (nothing, OFF + ["--output", "ambisonics", "--ambisonic-order", "0"], "--ambisonic-order"),
    "ambisonic_order_8": (nothing, OFF + ["--output", "ambisonics", "--ambisonic-order", "8"], "--ambisonic-order"),
    "ambisonic_order_text": (nothing, OFF + ["--output", "ambisonics", "--ambisonic-order", "three"], "--ambisonic-order"),
    "ambisonic_order_scene": (scene_with(**{"audio.output": "ambisonics", "audio.ambisonic_order": 9}), OFF, "audio.ambisonic_order"),
    "control_chars_key": (write("shoebox.json", '{"\\u001b[31mevil": 1}'), OFF, "shoebox.json"),
    # Scene-level values.
    "scene_empty": (write("shoebox.json", ""), OFF, "shoebox.json"),
    "scene_not_object": (write("shoebox.json", "[1,2,3]"), OFF, "shoebox.json"),
    "scene_binary": (write("shoebox.json", "\x00\x01\x02garbage"), OFF, "shoebox.json"),
    "scene_number_overflow": (write("shoebox.json", '{"mesh": 1e999}'), OFF, "shoebox.json"),
    "absorption_above_1": (scene_with(**{"materials.walls.absorption": [1.7] * 8}), OFF, "absorption"),
    "scattering_negative": (scene_with(**{"materials.walls.scattering": -0.5}), OFF, "scattering"),
    "transmission_loss_negative": (scene_with(**{"materials.walls.transmission_loss_db": -3}), OFF,
                                   "materials.walls.transmission_loss_db: -3 is outside"),
    "transmission_loss_nan": (scene_with(**{"materials.walls.transmission_loss_db": float("nan")}),
                              OFF, "shoebox.json"),
    "transmission_loss_string": (scene_with(**{"materials.walls.transmission_loss_db": "NaN"}), OFF,
                                 "materials.walls.transmission_loss_db"),
    "transmission_above_absorption": (scene_with(**{"materials.walls.transmission_loss_db": 3}),
                                      OFF, "materials.walls.transmission_loss_db[0]"),
    "frame_rate_1e6": (scene_with(**{"propagation.frame_rate": 1e6}), OFF, "frame_rate"),
    "cache_tau_too_many_frames": (scene_with(**{"propagation.cache_tau": 100, "propagation.frame_rate": 120,
                                                "propagation.dpc_weighting": "window"}), OFF,
                                  "propagation.cache_tau: 12000 frames of paths"),
    "sample_rate_8000": (scene_with(**{"audio.sample_rate": 8000}), OFF, "sample_rate"),
    "frame_rate_zero": (scene_with(**{"propagation.frame_rate": 0}), OFF, "frame_rate"),
    "sample_rate_zero": (scene_with(**{"audio.sample_rate": 0}), OFF, "sample_rate"),
    "ir_length_negative": (scene_with(**{"propagation.ir_length": -1}), OFF, "ir_length"),
    # A float field holds 0 for 1e-300: the message names the value as written and the rounding.
    "ir_length_rounds_to_zero": (scene_with(**{"propagation.ir_length": 1e-300}), OFF,
                                 "ir_length: 1e-300 rounds to 0 in single precision: 0 is outside (0, 60] s"),
    # 0 means "automatic" (the grid) and "path tracing" (tau): a nonzero value held as 0 is refused.
    "grid_spacing_rounds_to_zero": (scene_with(**{"wave": {"grid_spacing": 1e-300}}), OFF,
                                    "wave.grid_spacing: 1e-300 rounds to 0 in single precision"),
    "tau_flag_rounds_to_zero": (nothing, OFF + ["--tau", "1e-300"],
                                "--tau: 1e-300 rounds to 0 in single precision"),
    "patch_size_rounds_to_zero": (scene_with(**{"propagation.patch_size": 1e-300}), OFF,
                                  "patch_size: 1e-300 rounds to 0 in single precision: 0 must be > 0 m"),
    "radius_negative": (scene_with(**{"listener.radius": -1}), OFF, "radius"),
    "mesh_missing": (scene_with(mesh="none.obj"), OFF, "mesh"),
    # glTF levels (scene/model_reader.h): the line names the model file and what is wrong.
    "gltf_missing_buffer": (gltf_level(no_edit, "shoebox.gltf", drop_bin=True), OFF,
                            "shoebox.gltf: buffers[0].uri: referenced file 'shoebox.bin' not found"),
    "gltf_line_primitive": (gltf_level(gltf_set(("meshes", 0, "primitives", 1, "mode"), 1)), OFF,
                            'shoebox.glb: meshes[0].primitives[1].mode: mesh "room": 1 (LINES) is not supported'),
    "gltf_unmapped_material": (gltf_level(gltf_set(("materials", 2, "name"), "marble")), OFF,
                               'shoebox.glb: material marble: material "marble" is not defined'),
    "gltf_nan_in_accessor": (gltf_level(gltf_nan_vertex), OFF, 'shoebox.glb: mesh "bad" vertex 2: coordinate is NaN'),
    "gltf_animation_unknown_node": (gltf_level(gltf_door(node=0)), OFF,
                                    'shoebox.glb: animation "swing": moves node "room", which the scene does not name'),
    "gltf_animation_node_out_of_range": (gltf_level(gltf_door_on_node_9), OFF,
                                         "shoebox.glb: animations[0].channels[0].target.node: animation \"swing\": 9 is not an index of nodes"),
    # A .gltf level's buffer file is an input like the mesh: --offline replaced it (exit 0).
    "offline_is_gltf_buffer": (gltf_level(no_edit, "shoebox.gltf"),
                               ["shoebox.json", "--offline", "shoebox.bin", "--duration", "0.2"],
                               "--offline: 'shoebox.bin' is a file of the mesh (shoebox.gltf); refusing to overwrite it"),
    "ir_out_is_gltf_buffer": (gltf_level(no_edit, "shoebox.gltf"), OFF + ["--ir-out", "shoebox.bin"],
                              "--ir-out: 'shoebox.bin' is a file of the mesh (shoebox.gltf)"),
    "gltf_buffer_is_device": (gltf_level(no_edit, "shoebox.gltf", buffer_uri="/dev/zero"),
                              OFF, "shoebox.gltf: buffers[0].uri: '/dev/zero' is an absolute path"),
    "gltf_buffer_is_fifo": (steps(fifo("f.bin"), gltf_level(no_edit, "shoebox.gltf", buffer_uri="f.bin")),
                            OFF, "shoebox.gltf: buffers[0].uri: referenced file 'f.bin' is not a regular file"),
    "gltf_index_out_of_range": (gltf_index_out_of_range, OFF,
                                "shoebox.gltf: assimp read it only by changing it: Some faces had out-of-range indices"),
    "gltf_deep_nesting": (gltf_deep_nesting, OFF, "shoebox.gltf: JSON nested deeper than 64 levels"),
    "gltf_object_node_missing": (gltf_level(no_edit, objects=[{"name": "door"}]), OFF,
                                 'shoebox.json: objects[0].name: no node named "door"'),
    "gltf_cubic_spline": (gltf_level(gltf_door("CUBICSPLINE"), objects=[{"name": "door"}]), OFF,
                          "CUBICSPLINE interpolation is not supported"),
    # glTF levels stay in their folder, within their limits, and say what they hold
    # (scene/gltf_check.h): refused before assimp reads them.
    "gltf_buffer_passwd": (gltf_level(no_edit, "shoebox.gltf", buffer_uri="../../../../etc/passwd"), OFF,
                           "shoebox.gltf: buffers[0].uri: '../../../../etc/passwd' lies outside the level's folder"),
    "gltf_buffer_http": (gltf_level(no_edit, "shoebox.gltf", buffer_uri="http://localhost/shoebox.bin"), OFF,
                         "shoebox.gltf: buffers[0].uri: 'http://localhost/shoebox.bin' is a http: URI"),
    "gltf_buffer_symlink_out": (steps(symlink("/etc/passwd", "p.bin"), gltf_level(no_edit, "shoebox.gltf", buffer_uri="p.bin")),
                                OFF, "shoebox.gltf: buffers[0].uri: 'p.bin' lies outside the level's folder"),
    "gltf_node_tree_20000_deep": (gltf_level(gltf_node_chain(20000)), OFF, "lies more than 128 levels deep"),
    "gltf_json_chunk_0xfffffff0": (glb_bytes(12, 0xFFFFFFF0), OFF,
                                   "shoebox.glb: chunks[0].chunkLength: is 4294967280 bytes"),
    "gltf_position_byte": (gltf_level(gltf_set(("accessors", 0, "componentType"), 5120)), OFF,
                           'shoebox.glb: meshes[0].primitives[0].attributes.POSITION: mesh "room": POSITION is VEC3 of BYTE'),
    "gltf_line_loop": (gltf_level(gltf_set(("meshes", 0, "primitives", 0, "mode"), 2)), OFF, "2 (LINE_LOOP) is not supported"),
    "gltf_zero_rotation": (gltf_level(gltf_set(("nodes", 0, "rotation"), [0, 0, 0, 0])), OFF,
                           'shoebox.glb: nodes[0].rotation: node "room": [0,0,0,0] has zero length'),
    "gltf_sampler_output_short": (gltf_level(steps(gltf_door(), lambda g: g.doc["accessors"][g.doc["animations"][0]["samplers"][0]["output"]].update(count=1)), objects=[{"name": "door"}]),
                                  OFF, 'shoebox.glb: animations[0].samplers[0].output: animation "swing": 1 values for 2 keys'),
    "gltf_sampler_interpolation": (gltf_level(gltf_door("BOUNCY"), objects=[{"name": "door"}]), OFF,
                                   'animations[0].samplers[0].interpolation: animation "swing": "BOUNCY" is not a glTF interpolation'),
    "fbx_negative_unit_scale": (fbx_level(-100), OFF, "level.fbx: UnitScaleFactor: -100 is not a unit length"),
    "fbx_zero_unit_scale": (fbx_level(0), OFF, "level.fbx: FBX: The UnitScaleFactor must be non-zero"),
    "mesh_empty": (write("shoebox.obj", ""), OFF, "shoebox.obj"),
    "sources_empty": (scene_with(sources=[]), OFF, "sources"),
    # Source directivity (docs/scene-format.md, "sources[i].directivity").
    "directivity_unknown": (scene_with(**{"sources.0.directivity": "shotgun"}), OFF, 'shoebox.json: sources[0].directivity: "shotgun" is not one of'),
    "directivity_a_above_1": (scene_with(**{"sources.0.directivity": {"a": 1.5}}), OFF, "shoebox.json: sources[0].directivity.a: 1.5 is outside [0, 1]"),
    "directivity_a_negative": (scene_with(**{"sources.0.directivity": {"a": [0, 0, 0, 0, 0, 0, 0, -0.1]}}), OFF, "shoebox.json: sources[0].directivity.a[7]: -0.1 is outside [0, 1]"),
    "source_rotation_zero": (scene_with(**{"sources.0.rotation": [0, 0, 0, 0]}), OFF, "shoebox.json: sources[0].rotation: [0,0,0,0] has zero length"),
    "estimator_scene_bad": (scene_with(**{"propagation.estimator": "x"}), OFF, "estimator"),
    "tracing_scene_bad": (scene_with(**{"propagation.tracing": "sideways"}), OFF, "shoebox.json: propagation.tracing"),
    "tracing_flag_bad": (nothing, OFF + ["--tracing", "magic"], "--tracing"),
    "cache_pool_zero": (scene_with(**{"propagation.cache_pool_mb": 0}), OFF, "shoebox.json: propagation.cache_pool_mb"),
    "cache_pool_flag_nan": (nothing, OFF + ["--cache-pool-mb", "nan"], "--cache-pool-mb"),
    "rendering_scene_bad": (scene_with(**{"audio.rendering": "clustered"}), OFF, "shoebox.json: audio.rendering"),
    "rendering_flag_bad": (nothing, OFF + ["--rendering", "mixed"], "--rendering"),
    "late_buses_zero": (scene_with(**{"audio.late_buses": 0}), OFF, "shoebox.json: audio.late_buses: 0 is outside [1, 64]"),
    "late_buses_flag_65": (nothing, OFF + ["--late-buses", "65"], "--late-buses"),
    "late_buses_fraction": (scene_with(**{"audio.late_buses": 2.5}), OFF, "shoebox.json: audio.late_buses"),
    "cluster_angle_zero": (scene_with(**{"audio.cluster_angle": 0}), OFF, "shoebox.json: audio.cluster_angle"),
    "cluster_angle_flag_nan": (nothing, OFF + ["--cluster-angle", "nan"], "--cluster-angle"),
    # A value only single precision's rounding takes out of range names the flag and the value.
    "cluster_angle_flag_tiny": (nothing, OFF + ["--cluster-angle", "1e-300", "--rendering", "hybrid"], "--cluster-angle: 1e-300 rounds to 0 in single precision"),
    "teleport_not_bool": (scene_with(**{"listener.trajectory.1.teleport": "yes"}), OFF, "listener.trajectory[1].teleport"),
    # Finding 4 and 5: work and memory refused before any work, naming the setting to lower.
    "rays_1e8_order_10000": (scene_with(**{"propagation.rays_per_frame": 100000000, "propagation.max_order": 10000}), OFF[:-2], "rays_per_frame"),
    "ir_60s_192k_binaural": (scene_with(**{"propagation.ir_length": 60, "audio.sample_rate": 192000, "audio.output": "binaural"}), OFF, "ir_length"),
    # Entity counts: fixed bounds in the loader (docs/scene-format.md, "Limits").
    "sources_1000": (scene_with(sources=[{"name": f"s{i}", "position": [2, 1.6, 3.5], "signal": "signals/speech.wav"} for i in range(1000)]), OFF, "shoebox.json: sources: 1000 sources, more than the limit of 256"),
    "sources_257": (scene_with(sources=[{"name": f"s{i}", "position": [2, 1.6, 3.5], "signal": "signals/speech.wav"} for i in range(257)]), OFF, "shoebox.json: sources: 257 sources, more than the limit of 256"),
    "listeners_65": (without("listener", listeners=[{"name": f"l{i}", "position": [5, 1.6, 3.5]} for i in range(65)]), OFF, "shoebox.json: listeners: 65 listeners, more than the limit of 64"),
    # dpc-demo --bake: a bake of another scene, a damaged or missing file (docs/bake.md).
    "bake_of_other_scene": (bake_file(edit=scene_with(**{"sources.0.position": [3, 1.6, 3.5]})), OFF + ["--bake", "bake.h5"], "bake.h5: hash_sources: the bake's sources"),
    "bake_truncated": (bake_file(damage=truncate_half), OFF + ["--bake", "bake.h5"], "bake.h5: "),
    "bake_not_hdf5": (write("bake.h5", "not hdf5\n"), OFF + ["--bake", "bake.h5"], "bake.h5: not an HDF5 file"),
    "bake_missing": (nothing, OFF + ["--bake", "none.h5"], "none.h5: bake 'none.h5' not found"),
    "bake_directory": (mkdir("b.h5"), OFF + ["--bake", "b.h5"], "b.h5: bake 'b.h5' is a directory"),
    "bake_fifo": (fifo("b.h5"), OFF + ["--bake", "b.h5"], "b.h5: bake 'b.h5' is not a regular file"),
    "objects_257": (scene_with(objects=[{"name": f"o{i}", "mesh": "shoebox.obj", "trajectory": [{"t": 0, "position": [0, 0, 0]}]} for i in range(257)]), OFF, "shoebox.json: objects: 257 objects, more than the limit of 256"),
    # Names: printed in warnings (no control characters) and, for listeners, part of output
    # file names (no "/": "x/../../evil" wrote OUT-x/../../evil.wav two folders up).
    "listener_name_slash": (lambda d: (mkdir("out-x")(d), two_listeners("x/../evil")(d)), OFF, "shoebox.json: listeners[0].name: must not contain '/'"),
    "source_name_escape": (scene_with(**{"sources.0.name": "\x1b[2Jtalker"}), OFF, "shoebox.json: sources[0].name: must not contain control characters"),
    # A name too long for a file name (the temporary's suffix included): the field or the flag
    # that made it, not a bare "File name too long".
    "listener_name_too_long": (two_listeners("x" * 300), OFF, "shoebox.json: listeners[0].name: too long for the listener's --offline file: its file name of 308 bytes is too long (at most 244"),
    "listener_name_too_long_ir": (two_listeners("x" * 234), OFF + ["--ir-out", "impulse.wav"], "shoebox.json: listeners[0].name: too long for the listener's --ir-out file"),
    "offline_name_too_long": (nothing, ["shoebox.json", "--offline", "o" * 250 + ".wav"], "command line: --offline: its file name of 254 bytes is too long"),
    "er_out_path_too_long": (nothing, OFF + ["--er-out", "./" * 2100 + "er.csv"], "command line: --er-out: the path of 4206 bytes is too long"),
    "listener_name_nul": (two_listeners("a\x00b"), OFF, "listeners[0].name: contains a NUL character"),
    "signal_path_nul": (scene_with(**{"sources.0.signal": "signals/speech.wav\x00.x"}), OFF, "sources[0].signal: contains a NUL character"),
    "duplicate_key": (write_text(lambda t: t.replace('"propagation": {', '"propagation": {"rays_per_frame": 5,', 1)), OFF, 'shoebox.json: key "rays_per_frame" appears twice'),
    "radius_2e6": (scene_with(**{"listener.radius": 2e6}), OFF, "shoebox.json: listener.radius: 2000000 is outside (0, 1000000] m"),
    "layout_empty_name": (write("lay.json", '{"speakers": [{"name": "", "azimuth": 30}, {"name": "B", "azimuth": -30}]}'), OFF + ["--output", "layout:lay.json"], "lay.json: speakers[0].name: must not be empty"),
    "layout_name_escape": (write("lay.json", '{"speakers": [{"name": "\\u001b[2J", "azimuth": 30}, {"name": "B", "azimuth": -30}]}'), OFF + ["--output", "layout:lay.json"], "lay.json: speakers[0].name: must not contain control characters"),
    "layout_directory": (mkdir("lay.json"), OFF + ["--output", "layout:lay.json"], "lay.json: layout file 'lay.json' is a directory"),
    # Outputs: links followed, never replaced; options that an offline render would ignore.
    "offline_dangling_link_missing_folder": (symlink("nowhere/x.wav", "l.wav"), ["shoebox.json", "--offline", "l.wav"], "--offline: folder 'nowhere' does not exist"),
    "offline_link_loop": (lambda d: (symlink("b.wav", "a.wav")(d), symlink("a.wav", "b.wav")(d)), ["shoebox.json", "--offline", "a.wav"], "--offline: 'a.wav': too many levels of symbolic links"),
    "record_with_offline": (nothing, OFF + ["--record", "r.wav"], "--record: is for live runs"),
    "interactive_with_offline": (nothing, OFF + ["--interactive"], "--interactive: is for live runs"),
    "hrtf_directory": (mkdir("h.sofa"), OFF + ["--hrtf", "h.sofa"], "--hrtf: SOFA file 'h.sofa' is a directory"),
    "hrtf_fifo": (fifo("h.sofa"), OFF + ["--hrtf", "h.sofa"], "--hrtf: SOFA file 'h.sofa' is not a regular file"),
    # An existing output the user may not write is refused like a read-only folder (the rename
    # of the temporary would replace it). Root may write any file, so a file without any write
    # bit (chmod 444) is refused for root too; one that is only another user's is refused as
    # nobody (AS_NOBODY).
    "offline_read_only": (read_only("out.wav"), OFF, "--offline: 'out.wav': cannot write: the file is read-only"),
    "ir_out_read_only": (read_only("ir.wav"), OFF + ["--ir-out", "ir.wav"], "--ir-out: 'ir.wav': cannot write: the file is read-only"),
    "er_out_read_only_link": (steps(read_only("er.csv"), symlink("er.csv", "l.csv")), OFF + ["--er-out", "l.csv"], "--er-out: 'l.csv': cannot write: the file is read-only"),
    "offline_other_users_file": (steps(read_only("out.wav", 0o644), open_to_nobody), OFF, "--offline: 'out.wav': cannot write: the file is read-only"),
    # An output named for another format than its flag writes (a WAV under ir.csv, which
    # dpc-analyze then read as CSV).
    "ir_out_named_csv": (nothing, OFF + ["--ir-out", "ir.csv"], "--ir-out: 'ir.csv' names a CSV file, but --ir-out writes WAV or SOFA"),
    "er_out_named_wav": (nothing, OFF + ["--er-out", "er.wav"], "--er-out: 'er.wav' names a WAV file, but --er-out writes CSV"),
    "offline_in_read_only_folder": (read_only_folder("ro"), ["shoebox.json", "--offline", "ro/out.wav", "--duration", "0.2"], "--offline: folder"),
    "offline_named_json": (nothing, ["shoebox.json", "--offline", "out.JSON", "--duration", "0.2"], "--offline: 'out.JSON' names a JSON file"),
    "scene_link_loop": (lambda d: (symlink("b.json", "a.json")(d), symlink("a.json", "b.json")(d)), ["a.json", "--offline", "out.wav"], "a.json: scene file 'a.json' cannot be opened: Too many levels of symbolic links"),
    # A flag's value refused by a check of the settings together, or of the file it names,
    # names the flag (it named the scene file's field, which the user never wrote).
    "hrtf_flag_not_sofa": (nothing, OFF + ["--hrtf", "shoebox.json"], "command line: --hrtf: shoebox.json: not a valid SOFA file"),
    "tau_flag_window_too_long": (nothing, OFF + ["--tau", "3600", "--dpc-weighting", "window"], "command line: --tau: 54000 frames of paths"),
    "cache_memory_flag_tiny": (nothing, OFF + ["--cache-memory-mb", "0.001"], "command line: --cache-memory-mb: a budget of 1048 bytes"),
    # A pool below the tables the caches start with (it was exceeded from the first frame).
    "cache_pool_flag_tiny": (nothing, OFF + ["--cache-pool-mb", "0.001"], "command line: --cache-pool-mb: 0.001 MB is below the"),
    "cache_pool_scene_tiny": (scene_with(**{"propagation.cache_pool_mb": 0.01}), OFF, "shoebox.json: propagation.cache_pool_mb: 0.01 MB is below the"),
    # Flags that would change nothing in this run (accepted before, exit 0, without a word).
    "hrtf_with_mono": (write("h.sofa", "x"), OFF + ["--output", "mono", "--hrtf", "h.sofa"], "command line: --hrtf: is for binaural and ambisonic_binaural output (this run's output is mono)"),
    "ambisonic_order_with_mono": (nothing, OFF + ["--ambisonic-order", "2"], "command line: --ambisonic-order: is for ambisonics"),
    "max_re_with_stereo": (nothing, OFF + ["--output", "stereo", "--max-re"], "command line: --max-re: is for ambisonics output"),
    "binaural_decoder_with_mono": (nothing, OFF + ["--binaural-decoder", "sampling"], "command line: --binaural-decoder: is for ambisonic_binaural output"),
    "late_buses_per_source": (nothing, OFF + ["--rendering", "per_source", "--late-buses", "8"], "command line: --late-buses: is for hybrid rendering"),
    "device_offline": (nothing, OFF + ["--device", "nosuchdevice"], "command line: --device: is for live runs"),
    # A mesh of a format dpc does not read, named as it is (it read as an empty OBJ).
    "mesh_ply": (steps(write("cube.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n0 0 0\n"), scene_with(mesh="cube.ply")), OFF, "cube.ply: no OBJ faces in it: a mesh is read as OBJ unless it is glTF (.gltf, .glb) or FBX (.fbx), and \".ply\" is none of them"),
}

# Setups that load but cannot be meant: the render runs (exit 0, the output is written), and a
# one-line "warning:" on stderr names the scene and what is wrong.
OUT_ONLY = ["out.wav"]
WARN_CASES = {
    "listener_outside_room": (scene_with(listener={"position": [20, 1.6, 3.5], "radius": 0.5}), OFF, "listener 'listener' at (20, 1.6, 3.5)"),
    "source_outside_room": (scene_with(**{"sources.0.position": [2, 10, 3.5]}), OFF, "source 'talker' at (2, 10, 3.5)"),
    "radius_larger_than_room": (scene_with(listener={"position": [5, 1.5, 3.5], "radius": 30}), OFF, "larger than the room"),
    "radius_through_wall": (scene_with(listener={"position": [5, 1.5, 3.5], "radius": 2}), OFF, "reaches through a surface"),
    "radius_tiny": (scene_with(listener={"position": [5, 1.5, 3.5], "radius": 1e-30}), OFF, "m is tiny against the nearest surface"),
    "render_silent": (scene_with(listener={"position": [20, 1.6, 3.5], "radius": 0.5}), OFF, "is silent (empty energy response"),
    # A silent dry signal is named; the silent render is then not blamed on the geometry
    # (UNEXPECTED), and one far below -600 dBFS is not normalised (the gain overflowed float
    # and "out.wav: cannot write: a sample is not finite after the gain" blamed the output).
    "signal_all_zero": (float_wav("z.wav", 48000, [0.0] * 4800), OFF, "sources[0].signal: 'z.wav' is silent"),
    "signal_subnormal": (float_wav("t.wav", 48000, [1e-39 * math.sin(i * 0.06) for i in range(4800)]), OFF, "sources[0].signal: 't.wav' is silent"),
    # A render that ends before the direct sound arrives (0.1 ms; the talker is 6 m away) holds
    # float rounding, which normalising to -1 dBFS raised by about 400 dB.
    "render_before_first_sound": (nothing, ["shoebox.json", "--offline", "out.wav", "--duration", "0.0001", "--rays", "64"], "rounding, not sound"),
}
# Warning cases whose stderr must not hold this text (a misdiagnosis).
UNEXPECTED = {"signal_all_zero": "empty energy response", "signal_subnormal": "empty energy response"}


def digest(folder):
    out = {}
    for root, dirs, files in os.walk(folder):
        for name in files + dirs:
            p = os.path.join(root, name)
            st = os.lstat(p)
            if os.path.isfile(p) and not os.path.islink(p) and st.st_size < (1 << 30):
                out[p] = hashlib.sha256(open(p, "rb").read()).hexdigest()
            else:
                out[p] = (st.st_mode, st.st_size)
    return out


# A sanitized dpc-demo (scripts/asan.sh) reserves terabytes of shadow address space, so the
# address-space limit would stop it at start-up: ASan's own resident-memory limit replaces it.
SANITIZED = os.environ.get("DPC_BAD_INPUT_SANITIZED") == "1"


def limits():
    if not SANITIZED:
        resource.setrlimit(resource.RLIMIT_AS, (MEMORY_LIMIT_BYTES, MEMORY_LIMIT_BYTES))
    resource.setrlimit(resource.RLIMIT_CORE, (0, 0))


# Cases refused only because the address-space limit above leaves too little memory: without
# that limit (sanitized runs) the render would fit this machine and run for minutes.
NEEDS_MEMORY_LIMIT = {"ir_60s_192k_binaural"}


# Cases run as user nobody (uid 65534) when the suite runs as root; skipped otherwise (only root
# can give the case's files to another user).
AS_NOBODY = {"offline_other_users_file"}
NOBODY = 65534


def limits_as_nobody():
    limits()
    os.setgroups([])
    os.setgid(NOBODY)
    os.setuid(NOBODY)


def child_env():
    env = dict(os.environ)
    if SANITIZED:
        # A sanitizer report exits 86/87 (never the 1 of a clean refusal).
        env["ASAN_OPTIONS"] = f"hard_rss_limit_mb={MEMORY_LIMIT_BYTES >> 20}:exitcode=86:" + env.get("ASAN_OPTIONS", "")
        env["UBSAN_OPTIONS"] = "halt_on_error=1:print_stacktrace=1:exitcode=87:" + env.get("UBSAN_OPTIONS", "")
    return env


def run_case(demo, scenes, name):
    if SANITIZED and name in NEEDS_MEMORY_LIMIT:
        return None
    if name in AS_NOBODY and os.geteuid() != 0:
        return None
    warn = name in WARN_CASES
    setup, args, expect = WARN_CASES[name] if warn else CASES[name]
    with tempfile.TemporaryDirectory(prefix="dpc_bad_") as d:
        shutil.copy(os.path.join(scenes, "shoebox.json"), d)
        shutil.copy(os.path.join(scenes, "shoebox.obj"), d)
        shutil.copytree(os.path.join(scenes, "signals"), os.path.join(d, "signals"))
        setup(d)
        before = digest(d)
        try:
            p = subprocess.run([demo] + args, cwd=d, stdin=subprocess.DEVNULL, capture_output=True,
                               timeout=TIME_LIMIT_S, env=child_env(),
                               preexec_fn=limits_as_nobody if name in AS_NOBODY else limits)
        except subprocess.TimeoutExpired:
            return f"hung: no exit within {TIME_LIMIT_S} s"
        err = p.stderr.decode("utf-8", "replace")
        errors = [l for l in err.splitlines() if l.startswith("dpc-demo:")]
        problems = []
        if warn:
            warnings = [l for l in err.splitlines() if l.startswith("warning:") and expect in l]
            if p.returncode != 0:
                problems.append(f"exit status {p.returncode}, expected 0")
            if len(warnings) != 1:
                problems.append(f"{len(warnings)} warning lines with {expect!r}, expected 1")
            if errors:
                problems.append("an error line")
            if name in UNEXPECTED and UNEXPECTED[name] in err:
                problems.append(f"stderr holds {UNEXPECTED[name]!r}")
            created = sorted(set(digest(d)) - set(before))
            if [os.path.relpath(c, d) for c in created] != OUT_ONLY:
                problems.append(f"files created: {[os.path.relpath(c, d) for c in created]}, expected {OUT_ONLY}")
            if problems:
                return "; ".join(problems) + f"\n  stderr: {err.strip()[-600:]}"
            return None
        if p.returncode < 0:
            problems.append(f"killed by signal {signal.Signals(-p.returncode).name}")
        elif p.returncode != 1:
            problems.append(f"exit status {p.returncode}, expected 1")
        if len(errors) != 1:
            problems.append(f"{len(errors)} error lines, expected 1")
        elif expect not in errors[0]:
            problems.append(f"error line lacks {expect!r}")
        if re.search(r"[\x00-\x08\x0b-\x1f\x7f]", err):
            problems.append("control characters on stderr")
        after = digest(d)
        if after != before:
            changed = sorted(set(after.items()) ^ set(before.items()))
            problems.append(f"files created or changed: {[os.path.relpath(c[0], d) for c in changed]}")
        if problems:
            return "; ".join(problems) + f"\n  stderr: {err.strip()[-600:]}"
        return None


def main():
    names = sys.argv[3:]
    if names == ["--list"]:
        print(";".join(list(CASES) + list(WARN_CASES)))
        return 0
    demo, scenes = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    setups.DPC_BAKE = os.path.join(os.path.dirname(demo), "dpc-bake")
    failed = 0
    for name in names or list(CASES) + list(WARN_CASES):
        why = run_case(demo, scenes, name)
        print(f"{'FAIL' if why else 'ok  '} {name}" + (f": {why}" if why else ""))
        failed += why is not None
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
