"""`pip install --no-build-isolation .` into a fresh venv, as docs/python.md tells a user, then
the installed module imported from outside the source tree and an engine stepped with it
(ctest python:venv-install; label "full": it builds the library once more).

    venv_install.py PYTHON WORK_DIR

PYTHON makes the venv (with --system-site-packages: numpy, setuptools, wheel and pytest come
from Debian; pip is told --no-index, as on a machine without PyPI). The tracked sources are
copied to WORK_DIR/src first, so that the test neither writes into the checkout nor passes on
files that only the checkout holds; the venv is new each run. Exits 0 when every check passes.
"""
import os
import re
import shutil
import subprocess
import sys
import textwrap

SOURCE_DIR = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))


def tracked_files():
    """The files git tracks, or None outside a git checkout."""
    listed = subprocess.run(["git", "-C", SOURCE_DIR, "ls-files", "-z"], capture_output=True)
    if listed.returncode != 0:
        return None
    return [n for n in listed.stdout.decode().split("\0")
            if n and os.path.isfile(os.path.join(SOURCE_DIR, n))]


def sync_sources(dest):
    """dest becomes a copy of the tracked sources. A CMake tree pip left there (build-python-*)
    is kept, and files are copied with their times, so a second run compiles only what
    changed since the first (as a user's second pip install does); files no longer tracked
    are removed."""
    names = tracked_files()
    if names is None:  # not a git checkout: everything but build trees
        shutil.rmtree(dest, ignore_errors=True)
        shutil.copytree(SOURCE_DIR, dest, ignore=shutil.ignore_patterns("build*", ".git"))
        return
    keep = set(names)
    for root, dirs, files in os.walk(dest):
        dirs[:] = [d for d in dirs if not (root == dest and d.startswith("build-python-"))]
        for f in files:
            path = os.path.join(root, f)
            if os.path.relpath(path, dest) not in keep:
                os.remove(path)
    for name in names:
        os.makedirs(os.path.join(dest, os.path.dirname(name)), exist_ok=True)
        shutil.copy2(os.path.join(SOURCE_DIR, name), os.path.join(dest, name))


def run(args, **kwargs):
    print("+", " ".join(args), flush=True)
    done = subprocess.run(args, **kwargs)
    if done.returncode != 0:
        sys.exit(f"venv_install.py: exit status {done.returncode} from {args[:4]}:\n"
                 f"{done.stdout or ''}{done.stderr or ''}")
    return done


# Outside the source tree: what the installed module does, with a physics check (the direct
# sound of the shoebox's talker at 5 m is 1 / (4 pi r^2) at 63 Hz, in the bin of r / c).
STEP_ENGINE = textwrap.dedent("""
    import math, sys
    import numpy as np
    import dpc
    assert dpc.__file__.startswith(sys.prefix), (dpc.__file__, sys.prefix)
    e = dpc.Engine(sys.argv[1], rays_per_frame=256)
    e.set_listener_pose(0, [7.0, 1.6, 3.5])
    for _ in range(12):
        e.step()
    er = e.energy_response(0)
    k = int(5.0 / (331.3 * math.sqrt(1 + 20 / 273.15)) / 1e-3)
    assert (e.frames, e.sample_rate) == (12, 48000), (e.frames, e.sample_rate)
    assert abs(er[0, k] * 4 * math.pi * 25.0 - 1.0) < 0.01, er[0, k]
    print("stepped", dpc.__file__)
""")


def main():
    python, work = sys.argv[1], os.path.abspath(sys.argv[2])
    src, venv = os.path.join(work, "src"), os.path.join(work, "venv")
    sync_sources(src)
    shutil.rmtree(venv, ignore_errors=True)
    run([python, "-m", "venv", "--system-site-packages", venv])
    vpython = os.path.join(venv, "bin", "python")
    run([vpython, "-m", "pip", "install", "--no-build-isolation", "--no-index", src])
    shown = run([vpython, "-m", "pip", "show", "dpc"], capture_output=True, text=True).stdout
    version = re.search(r"project\(dpc VERSION ([0-9.]+)",
                        open(os.path.join(SOURCE_DIR, "CMakeLists.txt")).read()).group(1)
    assert f"Version: {version}" in shown, shown
    out = run([vpython, "-c", STEP_ENGINE, os.path.join(src, "scenes", "shoebox.json")],
              cwd=work, capture_output=True, text=True).stdout
    assert out.startswith("stepped " + venv), out
    # Without numpy (no site-packages at all) the import names what is missing.
    module_dir = os.path.dirname(out.split()[1])
    bare = subprocess.run([vpython, "-S", "-c", "import dpc"], cwd=work, capture_output=True,
                          text=True, env=dict(os.environ, PYTHONPATH=module_dir))
    assert bare.returncode != 0 and "dpc needs numpy" in bare.stderr, bare.stderr
    print(f"venv install: {out.strip()}")


if __name__ == "__main__":
    main()
