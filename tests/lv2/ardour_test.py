#!/usr/bin/python3
"""The dpc LV2 plugin in Ardour 7, headless: Ardour's Lua session tool (ardour7-lua, Debian's
ardour package) runs tests/lv2/ardour_session.lua, which creates a session on the dummy audio
backend, adds a track with the plugin fed by the backend's sine-wave input, plays, exports the
master bus, saves, closes, loads the session again, plays, exports and closes.

Usage: tests/lv2/ardour_test.py LV2_DIR [RUNS]   (LV2_DIR holds dpc.lv2, e.g. build/lv2)

Checks, each able to fail:
  1. every run exits with status 0 (a plugin that leaves a thread running after cleanup kills
     Ardour once the plugin's library is unloaded: before the fix, 3 of 3 runs ended in
     SIGSEGV after "closed again") and reaches every step of the script;
  2. sound came out: both exports (created and reloaded) carry the plugin's output, measured by
     sox (an instrument independent of dpc): the RMS level of the last second of each export
     above -60 dBFS (measured about -31 dBFS; a plugin that stays silent gives -inf);
  3. a bundle whose scene cannot be loaded (its mesh file is missing) still gives a working
     session: Ardour prints the plugin's error, naming the scene file, the exports are silent
     (RMS below -80 dBFS, measured -94: the 16-bit export's dither alone; the plugin plays
     silence, it does not pass its input through) and
     Ardour exits 0.
Ardour's configuration and caches go to a temporary HOME; LV2_PATH holds only LV2_DIR.
Runs take 10-60 s each (Ardour's start-up dominates; the script plays 2 x 3 s of real time).
"""
import os
import re
import shutil
import subprocess
import sys
import tempfile

URI = "urn:dpc:lv2:room"
SCRIPT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "ardour_session.lua")
STEPS = ["created", "plugin added", "exported created", "saved", "closed", "reloaded",
         "exported reloaded", "closed again"]

failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what, flush=True)
    if not ok:
        failures.append(what)
    return ok


def rms_db(wav, start, length):
    """RMS level (dBFS) of both channels of `wav` from `start` s for `length` s, by sox."""
    out = subprocess.run(["sox", wav, "-n", "trim", str(start), str(length), "stats"],
                         capture_output=True, text=True, check=True).stderr
    m = re.search(r"^RMS lev dB\s+(\S+)", out, re.M)
    return float(m.group(1)) if m else float("nan")


def run_ardour(lv2dir, home, work, label, wait=120):
    """One run of the session script, which plays until the plugin sounds (at most `wait` s)
    before each export; returns (exit status, output, export folder)."""
    session, exports = os.path.join(work, label), os.path.join(work, label + "-export")
    env = dict(os.environ, HOME=home, LV2_PATH=lv2dir, XDG_CONFIG_HOME=os.path.join(home, ".config"),
               XDG_CACHE_HOME=os.path.join(home, ".cache"))
    try:
        p = subprocess.run(["ardour7-lua", SCRIPT, session, exports, URI, str(wait)], env=env,
                           stdin=subprocess.DEVNULL, capture_output=True, text=True, timeout=300)
        return p.returncode, p.stdout + p.stderr, exports
    except subprocess.TimeoutExpired as e:
        return "timeout", (e.stdout or b"").decode(errors="replace"), exports


def reached(output):
    return [s for s in STEPS if "dpc-test: " + s + "\n" in output]


def broken_bundle(lv2dir, work):
    """A copy of dpc.lv2 (binary and Turtle linked) whose default scene names a missing mesh."""
    src, dst = os.path.join(lv2dir, "dpc.lv2"), os.path.join(work, "broken-lv2", "dpc.lv2")
    os.makedirs(os.path.join(dst, "scene"))
    for name in os.listdir(src):
        if name != "scene":
            os.symlink(os.path.join(src, name), os.path.join(dst, name))
    with open(os.path.join(src, "scene", "room.json")) as f:
        scene = f.read().replace('"shoebox.obj"', '"missing.obj"')
    with open(os.path.join(dst, "scene", "room.json"), "w") as f:
        f.write(scene)
    return os.path.dirname(dst)


def main():
    lv2dir = os.path.abspath(sys.argv[1])
    runs = int(sys.argv[2]) if len(sys.argv) > 2 else 1
    work = tempfile.mkdtemp(prefix="dpc_ardour_")
    home = os.path.join(work, "home")
    os.makedirs(home)
    try:
        clean = 0
        for i in range(runs):
            status, output, exports = run_ardour(lv2dir, home, work, "run%d" % i)
            steps = reached(output)
            exited = status == 0 and steps == STEPS
            clean += exited
            ok = check(exited, "run %d: exit status %s after %s"
                       % (i + 1, status, steps[-1:] or "no step"))
            for name in ("created", "reloaded"):
                wav = os.path.join(exports, name + ".wav")
                level = rms_db(wav, 3, 1) if os.path.exists(wav) else float("-inf")
                ok = check(level > -60, "run %d, %s session: the plugin's output at %.1f dBFS "
                           "RMS (above -60)" % (i + 1, name, level)) and ok
            if not ok:
                print(output[-3000:])
        print("ardour_test: %d of %d runs exited 0 after every step" % (clean, runs))
        status, output, exports = run_ardour(broken_bundle(lv2dir, work), home, work, "broken",
                                             wait=0)
        check(status == 0 and reached(output) == STEPS,
              "a scene that does not load: exit status %s after every step" % status)
        error = re.search(r"\[ERROR\]: dpc: .*missing\.obj.*", output)
        print(error.group(0) if error else output[-3000:])
        check(error is not None,
              "a scene that does not load: Ardour shows the plugin's error naming missing.obj")
        wav = os.path.join(exports, "created.wav")
        level = rms_db(wav, 0, 4) if os.path.exists(wav) else float("nan")
        check(level < -80, "a scene that does not load: the plugin plays silence (%.1f dBFS)"
              % level)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    print("ardour_test: %s" % ("OK" if not failures else "%d FAILED" % len(failures)))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
