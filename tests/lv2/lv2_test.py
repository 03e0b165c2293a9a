#!/usr/bin/python3
"""Headless checks of the dpc LV2 bundle with lilv's tools (no audio device, no numpy).

Usage: tests/lv2/lv2_test.py LV2_DIR [DPC_DEMO] (LV2_DIR holds dpc.lv2, e.g. build/lv2 or
PREFIX/lib/lv2). Checks, each able to fail:
  1. lv2_validate accepts manifest.ttl and dpc.ttl against the installed LV2 specifications;
  2. lv2ls lists urn:dpc:lv2:room with LV2_PATH=LV2_DIR;
  3. lv2apply renders an impulse through the default scene (10 x 7 x 3 m shoebox, source 4 m
     from the listener): a stereo file as long as the input, finite, not silent, with the
     direct sound where physics puts it (input time + latency + r / c) and reverberant: more
     energy after the direct sound than in it (4 m is far beyond this room's critical distance
     of about 1 m, so the reverberant field carries ~90 % of the energy), decaying with time;
  4. moving the listener from 1 m to 6 m from the source lowers the direct sound by
     20 log10(6) = 15.6 dB (inverse square law; ISO 9613-1 air absorption over the extra 5 m
     adds about 0.4 dB to an impulse, whose energy sits mostly in the 4 and 8 kHz octaves),
     within 2 dB: the band-filtered arrival is read in +-0.25 ms, which holds ~94 % of it at
     1 m, and diffuse sound arriving in the same 0.5 ms adds a little at 6 m. The total
     energy falls too (less direct sound, same reverberant field).
  5. with DPC_DEMO: the same scene and static pose rendered by `dpc-demo --offline` (the
     impulse as the source's signal, unity gain) matches the plugin's output: the plugin's
     direct sound comes exactly LATENCY frames later, its level agrees within 0.5 dB (both
     compute it analytically), and the energy in 0-50, 50-200 and 200-600 ms after it agrees
     within 1.5 dB. Not bit for bit: the offline renderer updates the impulse response 15 times
     per second of audio, the plugin 15 times per second of wall-clock time while lv2apply runs
     faster than real time, and each propagation frame's diffuse estimate carries Monte Carlo
     noise (2048 rays per frame: a few per cent of the energy in windows this wide).
  6. every pose control port (lv2info's Minimum and Maximum of the installed dpc.ttl) given a
     value beyond its maximum, below its minimum and NaN: lv2apply exits 0 with a finite
     output, and the plugin logs exactly one line for that port naming the value and the
     declared range it was clamped to (so the plugin's clamp and the .ttl agree); values at
     the bounds log nothing;
  7. an 8 kHz host (an 8 kHz input file): the plugin refuses to instantiate (returns NULL),
     logging the sample rate's limit, instead of playing silence. lv2apply then fails (it
     dereferences the NULL instance and dies of SIGSEGV, a host bug outside dpc), so the
     check is a non-zero exit and the logged line.
  8. the AmbiX plugins (orders 1 and 3): lv2ls lists them, lv2apply writes (N + 1)^2 finite
     channels, and the direct sound's first-order channels point where the geometry says:
     source (3, 1.6, 5.5), listener (7, 1.6, 3.5) facing -x (yaw 180 degrees), so the source
     is 4 m ahead and 2 m to the left (+z is the listener's left at this yaw), azimuth
     atan(2 / 4) = 26.57 degrees, elevation 0. A plane wave in ACN/SN3D has W = s, Y = s sin(az)
     cos(el), Z = s sin(el), X = s cos(az) cos(el) (AmbiX; Nachbar et al. 2011), so the
     least-squares ratios (Y, Z, X) / W over +-0.25 ms around the direct sound give the
     direction: within 2 degrees, its length 1 within 0.05 (only the direct sound arrives in
     that window: the first reflection comes 3.6 ms later).
"""
import math
import os
import shutil
import struct
import subprocess
import sys
import tempfile

from lv2_wav import energy, read_wav, write_wav

URI = "urn:dpc:lv2:room"
RATE = 48000
LATENCY = 256   # the default scene's audio.block_size: the plugin's reported latency
C = 343.2       # m/s: the scene's speed of sound at 20 degrees C (331.3 sqrt(1 + T / 273.15))


failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        failures.append(what)


def render(work, name, x, controls, uri=URI):
    inp, out = os.path.join(work, name + "-in.wav"), os.path.join(work, name + ".wav")
    write_wav(inp, x, RATE)
    cmd = ["lv2apply", "-i", inp, "-o", out]
    for k, v in controls.items():
        cmd += ["-c", k, str(v)]
    subprocess.run(cmd + [uri], check=True, env=env)
    return read_wav(out)


def check_ambix(work, impulse, t0):
    """8. The AmbiX plugins: channel count and the direct sound's direction."""
    listed = subprocess.run(["lv2ls"], capture_output=True, text=True, env=env).stdout.split()
    az_expected = math.degrees(math.atan2(2.0, 4.0))
    arrival = t0 + LATENCY + round(math.hypot(4.0, 2.0) / C * RATE)
    wd = int(0.00025 * RATE)
    for order in (1, 3):
        uri = "urn:dpc:lv2:room-ambix%d" % order
        check(uri in listed, "lv2ls lists " + uri)
        chs, _ = render(work, "ambix%d" % order, impulse, {"source_z": 5.5}, uri)
        want = (order + 1) ** 2
        check(len(chs) == want and all(math.isfinite(v) for ch in chs for v in ch),
              "%s: %d finite channels (got %d)" % (uri, want, len(chs)))
        if len(chs) != want:
            continue
        peak = max(range(arrival - 4 * wd, arrival + 4 * wd), key=lambda i: chs[0][i] ** 2)
        window = range(peak - wd, peak + wd + 1)
        ww = sum(chs[0][i] ** 2 for i in window)
        y, z, x = (sum(chs[0][i] * chs[c][i] for i in window) / ww for c in (1, 2, 3))
        az = math.degrees(math.atan2(y, x))
        el = math.degrees(math.atan2(z, math.hypot(x, y)))
        length = math.sqrt(x * x + y * y + z * z)
        check(abs(az - az_expected) < 2.0 and abs(el) < 2.0 and abs(length - 1.0) < 0.05,
              "%s: direct sound from azimuth %.2f, elevation %.2f deg, |(Y,Z,X)/W| %.3f "
              "(expected %.2f, 0, 1: within 2 deg, 0.05)" % (uri, az, el, length, az_expected))


def declared_ranges():
    """{symbol: (minimum, maximum)} of the plugin's input control ports, as lv2info reads
    dpc.ttl."""
    info = subprocess.run(["lv2info", URI], env=env, check=True, capture_output=True,
                          text=True).stdout
    ranges = {}
    for block in info.split("\n\n"):
        fields = dict(line.strip().split(":", 1) for line in block.splitlines()
                      if ":" in line and not line.strip().startswith("http"))
        if "ControlPort" in block and "InputPort" in block and "Minimum" in fields:
            ranges[fields["Symbol"].strip()] = (float(fields["Minimum"]),
                                                float(fields["Maximum"]))
    return ranges


def apply_controls(work, controls, rate=RATE):
    """lv2apply on 0.2 s of noise-free impulse: (exit status, stderr, channels or None)."""
    inp, out = os.path.join(work, "ctl-in.wav"), os.path.join(work, "ctl.wav")
    x = [0.0] * (rate // 5)
    x[10] = 1.0
    write_wav(inp, x, rate)
    cmd = ["lv2apply", "-i", inp, "-o", out]
    for k, v in controls.items():
        cmd += ["-c", k, str(v)]
    r = subprocess.run(cmd + [URI], env=env, capture_output=True, text=True)
    return r.returncode, r.stderr, (read_wav(out)[0] if r.returncode == 0 else None)


def check_port_ranges(work):
    ranges = declared_ranges()
    check(len(ranges) == 7, "lv2info lists 7 pose control ports (%d)" % len(ranges))
    for symbol, (lo, hi) in sorted(ranges.items()):
        for value, to in ((hi * 10 + 1, hi), (lo * 10 - 1, lo), (float("nan"), None)):
            status, err, chs = apply_controls(work, {symbol: value})
            lines = [l for l in err.splitlines() if "port %s:" % symbol in l]
            expected = "is outside its range [%g, %g]" % (lo, hi)
            finite = chs is not None and all(math.isfinite(v) for ch in chs for v in ch)
            check(status == 0 and finite and len(lines) == 1 and expected in lines[0] and
                  (to is None or lines[0].endswith("clamped to %g (logged once)" % to)),
                  "%s = %g: exit %d, finite output, one log line naming [%g, %g]: %s"
                  % (symbol, value, status, lo, hi, lines))
    status, err, _ = apply_controls(work, {s: r[1] for s, r in ranges.items()})
    check(status == 0 and "outside" not in err, "every port at its maximum: nothing logged")
    status, err, _ = apply_controls(work, {}, rate=8000)
    check(status != 0 and "sample_rate: 8000 is outside [16000, 192000] Hz" in err,
          "8 kHz host: refused, naming the sample rate's limit (exit %d): %s"
          % (status, err.strip().splitlines()[:1]))


lv2dir = os.path.abspath(sys.argv[1])
bundle = os.path.join(lv2dir, "dpc.lv2")
env = dict(os.environ, LV2_PATH=lv2dir)

r = subprocess.run(["lv2_validate", os.path.join(bundle, "manifest.ttl"),
                    os.path.join(bundle, "dpc.ttl")], capture_output=True, text=True)
errors = [l for l in (r.stdout + r.stderr).splitlines() if "error" in l.lower()]
check(r.returncode == 0 and "Found 0 errors" in r.stdout + r.stderr,
      "lv2_validate: " + (errors[0] if errors else "0 errors"))

r = subprocess.run(["lv2ls"], capture_output=True, text=True, env=env)
check(URI in r.stdout.split(), "lv2ls lists " + URI + " from LV2_PATH=" + lv2dir)

work = tempfile.mkdtemp()
try:
    t0 = int(0.05 * RATE)
    n = int(2.0 * RATE)
    impulse = [0.0] * n
    impulse[t0] = 1.0

    # 3. Default pose: source (3, 1.6, 3.5), listener (7, 1.6, 3.5): r = 4 m.
    chs, rate = render(work, "default", impulse, {})
    check(len(chs) == 2 and rate == RATE and len(chs[0]) == n,
          "stereo output, %d Hz, %d frames (got %d ch, %d Hz, %d frames)"
          % (RATE, n, len(chs), rate, len(chs[0])))
    finite = all(math.isfinite(v) for ch in chs for v in ch)
    total = energy(chs, 0, n)
    check(finite, "every sample finite")
    check(total > 1e-8, "not silent (energy %.3g)" % total)
    arrival = t0 + LATENCY + round(4.0 / C * RATE)
    w = int(0.0015 * RATE)
    peak = max(range(n), key=lambda i: chs[0][i] ** 2 + chs[1][i] ** 2)
    check(abs(peak - arrival) <= w,
          "direct sound at sample %d, expected %d (input + latency + r/c) +- %d"
          % (peak, arrival, w))
    direct = energy(chs, arrival - w, arrival + w)
    after = energy(chs, arrival + w, n)
    check(after > direct, "reverberant: energy after the direct sound %.3g > direct %.3g "
          "(fraction %.2f)" % (after, direct, after / total))
    early = energy(chs, arrival + int(0.1 * RATE), arrival + int(0.3 * RATE))
    late = energy(chs, arrival + int(0.6 * RATE), arrival + int(0.8 * RATE))
    check(late > 0 and early > 2 * late,
          "decaying tail: 100-300 ms %.3g > 2 x 600-800 ms %.3g" % (early, late))

    # 4. Listener 1 m and 6 m from the source, facing it.
    near, _ = render(work, "near", impulse, {"listener_x": 4.0})
    far, _ = render(work, "far", impulse, {"listener_x": 9.0})
    a1 = t0 + LATENCY + round(1.0 / C * RATE)
    a6 = t0 + LATENCY + round(6.0 / C * RATE)
    wd = int(0.00025 * RATE)
    d1, d6 = energy(near, a1 - wd, a1 + wd), energy(far, a6 - wd, a6 + wd)
    drop = 10 * math.log10(d1 / d6) if d1 > 0 and d6 > 0 else float("nan")
    check(abs(drop - 20 * math.log10(6.0)) < 2.0,
          "direct sound 1 m -> 6 m: %.1f dB lower (inverse square law: 15.6 +- 2 dB)" % drop)
    e1, e6 = energy(near, 0, n), energy(far, 0, n)
    check(e1 > e6, "total energy falls with distance (%.3g at 1 m, %.3g at 6 m)" % (e1, e6))

    # 5. Against the offline renderer.
    if len(sys.argv) > 2:
        import json
        with open(os.path.join(bundle, "scene", "room.json")) as f:
            scene = json.load(f)
        write_wav(os.path.join(work, "impulse.wav"), impulse, RATE)
        scene["mesh"] = os.path.join(bundle, "scene", scene["mesh"])
        scene["sources"][0]["signal"] = os.path.join(work, "impulse.wav")
        with open(os.path.join(work, "offline.json"), "w") as f:
            json.dump(scene, f)
        off = os.path.join(work, "offline.wav")
        subprocess.run([sys.argv[2], os.path.join(work, "offline.json"), "--offline", off,
                        "--gain-db", "0", "--duration", str(n / RATE), "--quiet"], check=True)
        ref, _ = read_wav(off)
        pk = max(range(len(ref[0])), key=lambda i: ref[0][i] ** 2 + ref[1][i] ** 2)
        check(peak - pk == LATENCY, "plugin's direct sound %d frames after the offline "
              "render's (expected the latency, %d)" % (peak - pk, LATENCY))
        def db(a, b):
            return 10 * math.log10(a / b) if a > 0 and b > 0 else float("inf")
        dd = db(energy(chs, peak - wd, peak + wd), energy(ref, pk - wd, pk + wd))
        check(abs(dd) < 0.5, "direct sound: plugin - offline = %+.2f dB (within 0.5 dB)" % dd)
        for a_ms, b_ms in ((0, 50), (50, 200), (200, 600)):
            a, b = int(a_ms * RATE / 1000) + wd, int(b_ms * RATE / 1000) + wd
            d = db(energy(chs, peak + a, peak + b), energy(ref, pk + a, pk + b))
            check(abs(d) < 1.5, "%d-%d ms after the direct sound: plugin - offline = %+.2f dB "
                  "(within 1.5 dB)" % (a_ms, b_ms, d))

    # 6 and 7. Control ports beyond their declared ranges; a host rate below the limit.
    check_port_ranges(work)
    check_ambix(work, impulse, t0)
finally:
    shutil.rmtree(work, ignore_errors=True)

print("lv2_test: %s" % ("OK" if not failures else "%d FAILED" % len(failures)))
sys.exit(1 if failures else 0)
