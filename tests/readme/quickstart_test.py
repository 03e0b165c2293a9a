#!/usr/bin/env python3
"""The README's quickstarts, run as written (ctest readme:quickstarts).

    quickstart_test.py SOURCE_DIR

Every fenced `sh` block after a `<!-- quickstart: NAME -->` line of SOURCE_DIR/README.md runs in
bash from a scratch folder that mirrors the source tree (its folders linked, so the block's
relative paths mean what they mean in the checkout, and what it writes lands in the scratch
folder), with HOME pointing into the scratch folder (the blocks install to $HOME/dpc) and
Debian's interpreters first on PATH, as on a fresh Debian 12. Each result is checked as a user
would look at it: the Python block prints 8 finite reverberation times, the C block writes a
WAV, the plugin block writes a WAV, the studio block prints a URL that serves the page. A
quickstart this test does not know, or a known one missing from the README, fails.
Exits 0 when all pass; otherwise prints what failed.
"""
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import urllib.request

SOURCE = os.path.abspath(sys.argv[1])


def quickstarts(readme):
    """{name: the commands} of the README's quickstart blocks."""
    text = open(readme, encoding="utf-8").read()
    found = re.findall(r"<!-- quickstart: (\w+) -->\s*```sh\n(.*?)```", text, re.S)
    return {name: body for name, body in found}


def scratch_tree():
    """A folder whose entries link to the checkout's (not .git), to run the blocks in."""
    root = tempfile.mkdtemp(prefix="dpc-quickstart-")
    for name in os.listdir(SOURCE):
        if name != ".git":
            os.symlink(os.path.join(SOURCE, name), os.path.join(root, name))
    os.makedirs(os.path.join(root, "home"))
    return root


def environment(root):
    env = dict(os.environ, HOME=os.path.join(root, "home"))
    env["PATH"] = "/usr/bin:/bin:" + env.get("PATH", "")
    env.pop("PYTHONPATH", None)
    env.pop("LV2_PATH", None)
    return env


def run(block, root, timeout=900):
    done = subprocess.run(["bash", "-euo", "pipefail", "-c", block], cwd=root, env=environment(root),
                          capture_output=True, text=True, timeout=timeout)
    if done.returncode != 0:
        raise AssertionError(f"exit {done.returncode}:\n{done.stdout[-2000:]}{done.stderr[-2000:]}")
    return done.stdout + done.stderr


def is_wav(path):
    with open(path, "rb") as f:
        head = f.read(12)
    return head[:4] == b"RIFF" and head[8:12] == b"WAVE" and os.path.getsize(path) > 4096


def check_python(block, root):
    out = run(block, root)
    line = next(l for l in out.splitlines() if l.startswith("T30 (s)"))
    values = [float(v) for v in re.findall(r"[-+]?\d*\.\d+|\d+", line.split(":", 1)[1])]
    # The shoebox's T30 is about 1 s (Sabine from its materials: 0.9 to 1.3 s per band).
    assert len(values) == 8 and all(0.3 < v < 3.0 for v in values), line


def check_c(block, root):
    run(block, root)
    assert is_wav(os.path.join(root, "c.wav")), "c.wav"


def check_plugin(block, root):
    run(block, root)
    assert is_wav(os.path.join(root, "wet.wav")), "wet.wav"


def check_studio(block, root):
    proc = subprocess.Popen(["bash", "-euo", "pipefail", "-c", "exec " + block.strip()], cwd=root,
                            env=environment(root), stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True)
    try:
        url, deadline = None, time.time() + 600
        while url is None and time.time() < deadline:
            line = proc.stdout.readline()
            if not line:
                break
            m = re.search(r"studio: (http://127\.0\.0\.1:\d+/\?token=\w+)", line)
            url = m and m.group(1)
        assert url, "no studio URL printed"
        with urllib.request.urlopen(url, timeout=30) as page:
            assert page.status == 200 and b"<html" in page.read().lower(), url
    finally:
        proc.send_signal(signal.SIGINT)
        try:
            proc.wait(timeout=30)
        except subprocess.TimeoutExpired:
            proc.kill()
    assert proc.returncode == 0, f"dpc-demo --studio exit {proc.returncode} after SIGINT"


CHECKS = {"python": check_python, "c": check_c, "plugin": check_plugin, "studio": check_studio}


def main():
    blocks = quickstarts(os.path.join(SOURCE, "README.md"))
    failed = sorted(set(CHECKS) ^ set(blocks))
    for name in failed:
        print(f"quickstart {name}: in {'the test' if name in CHECKS else 'README.md'} only")
    root = scratch_tree()
    try:
        for name, block in blocks.items():
            if name not in CHECKS:
                continue
            start = time.time()
            try:
                CHECKS[name](block, root)
                print(f"quickstart {name}: ok ({time.time() - start:.0f} s)")
            except (AssertionError, subprocess.TimeoutExpired, StopIteration) as e:
                failed.append(name)
                print(f"quickstart {name}: FAILED: {e!r}")
    finally:
        shutil.rmtree(root, ignore_errors=True)
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
