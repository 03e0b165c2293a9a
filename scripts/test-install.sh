#!/usr/bin/env bash
# Installs dpc from ./build into a fresh prefix, builds both examples out of tree against it
# (C with pkg-config, C++ with find_package(dpc)), runs them on scenes/shoebox.json and checks
# that each writes a non-silent, finite WAV; then checks the installed LV2 bundle
# (lib/lv2/dpc.lv2) with lilv's tools (tests/lv2/lv2_test.py).
# Usage: scripts/test-install.sh (after build.sh)
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# DPC_KEEP_WAVS=DIR keeps the two renderings for listening.
prefix=$work/prefix
targets=(dpc_shared dpc_static)
# The plugin is configured only where lv2-dev is installed.
help=$(cmake --build build --target help 2>/dev/null | sed 's/^\.\.\. //')
if grep -q '^dpc_lv2:' <<<"$help"; then
  targets+=(dpc_lv2)
fi
# The Python module is configured only where pybind11-dev is installed.
if grep -q '^dpc_python:' <<<"$help"; then
  targets+=(dpc_python)
fi
cmake --build build -j"$(nproc)" --target "${targets[@]}" >/dev/null
cmake --install build --prefix "$prefix" >/dev/null
# No build-tree or source-tree path may leak into the installed package files.
if grep -rl -e "$root/build" -e "$root/" "$prefix/lib" --include='*.cmake' --include='*.pc'; then
  echo "test-install: build-tree path in the installed package" >&2
  exit 1
fi
libdir=$(dirname "$(find "$prefix" -name 'libdpc.so' | head -1)")
PKG_CONFIG_PATH=$libdir/pkgconfig cmake -S examples/c -B "$work/c" >/dev/null
cmake --build "$work/c" >/dev/null
cmake -S examples/cpp -B "$work/cpp" -DCMAKE_PREFIX_PATH="$prefix" >/dev/null
cmake --build "$work/cpp" >/dev/null
# The static archive links on its own with the libraries dpc.pc lists as private (no
# unresolved symbol), and the program runs without libdpc.so.
cc -o "$work/play_scene_static" examples/c/play_scene.c -I"$prefix/include" \
  "$libdir/libdpc.a" $(PKG_CONFIG_PATH=$libdir/pkgconfig pkg-config --static --libs-only-l dpc |
  sed 's/-ldpc //')
"$work/play_scene_static" scenes/shoebox.json "$work/c-static.wav"
/usr/bin/python3 scripts/wavcheck.py "$work/c-static.wav"
export LD_LIBRARY_PATH=$libdir${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
"$work/c/play_scene" scenes/shoebox.json "$work/c.wav"
"$work/cpp/play_scene_cpp" scenes/shoebox.json "$work/cpp.wav"
[[ -n "${DPC_KEEP_WAVS:-}" ]] && cp "$work/c.wav" "$work/cpp.wav" "$DPC_KEEP_WAVS"/
/usr/bin/python3 scripts/wavcheck.py "$work/c.wav"
/usr/bin/python3 scripts/wavcheck.py "$work/cpp.wav"
if [[ -d $libdir/lv2/dpc.lv2 ]]; then
  # The installed bundle finds libdpc.so through its RPATH, not LD_LIBRARY_PATH.
  env -u LD_LIBRARY_PATH /usr/bin/python3 tests/lv2/lv2_test.py "$libdir/lv2"
fi
module=$(find "$prefix" -name 'dpc.cpython-*.so' | head -1)
if [[ -n $module ]]; then
  # Installed in <prefix>/lib/python3.X/dist-packages (docs/python.md): importable from there
  # by Debian's python3, without the build tree.
  (cd "$work" && env -u LD_LIBRARY_PATH PYTHONPATH="$(dirname "$module")" /usr/bin/python3 -c \
    "import dpc; r = dpc.render('$root/scenes/shoebox.json', duration=0.2, rays_per_frame=256);
assert r.impulse_response(0).shape[0] == 1 and abs(r.output).max() > 0")
fi
echo "test-install: OK"
