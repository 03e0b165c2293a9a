#!/usr/bin/env bash
# Installs dpc from ./build into a fresh prefix, builds both examples out of tree against it
# (C with pkg-config, C++ with find_package(dpc)), runs them on scenes/shoebox.json (and the C
# one on a 16-channel AmbiX copy of it) and checks that each writes a non-silent, finite WAV;
# checks that find_package and pkg-config accept the same version requests, and that a
# program compiled against earlier releases' dpc.h (0.6.0, 0.7.0 and 0.8.0, tests/install/) runs
# against the installed library with the results of the same program compiled against the new one
# (dpc.h, "Versions and growth rule"); then checks the installed LV2 bundle (lib/lv2/dpc.lv2)
# with lilv's tools (tests/lv2/lv2_test.py) and the README's LV2_PATH line.
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

# The C example sizes its outputs from dpc_engine_output_channels: third-order AmbiX writes
# 16 channels (sox's soxi counts them), every one finite, W not silent.
/usr/bin/python3 - "$root/scenes/shoebox.json" "$work/ambix.json" <<'PY'
import json, os, sys
scene = json.load(open(sys.argv[1]))
folder = os.path.dirname(sys.argv[1])
scene["mesh"] = os.path.join(folder, scene["mesh"])
for source in scene["sources"]:
    source["signal"] = os.path.join(folder, source["signal"])
scene["audio"].update(output="ambisonics", ambisonic_order=3)
json.dump(scene, open(sys.argv[2], "w"))
PY
"$work/c/play_scene" "$work/ambix.json" "$work/ambix.wav"
[[ $(soxi -c "$work/ambix.wav") == 16 ]] || { echo "test-install: AmbiX: not 16 channels" >&2; exit 1; }
/usr/bin/python3 scripts/wavcheck.py "$work/ambix.wav"

# find_package(dpc X.Y) and pkg-config's "dpc >= X.Y" accept the same requests (dpc.h,
# "Versions and growth rule"): an older one of this major version and the current one, not a
# newer minor version nor the next major one.
IFS=. read -r major minor _ < <(PKG_CONFIG_PATH=$libdir/pkgconfig pkg-config --modversion dpc)
mkdir -p "$work/request"
printf '%s\n' 'cmake_minimum_required(VERSION 3.16)' 'project(request NONE)' \
  'find_package(dpc ${REQUEST} REQUIRED)' >"$work/request/CMakeLists.txt"
for request in 0.3:yes "$major.$minor":yes "$major.$((minor + 1))":no "$((major + 1)).0":no; do
  version=${request%:*} cmake_accepts=no pc_accepts=no
  cmake -S "$work/request" -B "$work/request/$version" -DREQUEST="$version" \
    -DCMAKE_PREFIX_PATH="$prefix" >/dev/null 2>&1 && cmake_accepts=yes
  PKG_CONFIG_PATH=$libdir/pkgconfig pkg-config --exists "dpc >= $version" && pc_accepts=yes
  echo "request dpc $version: find_package $cmake_accepts, pkg-config $pc_accepts"
  if [[ $cmake_accepts != "${request#*:}" || $pc_accepts != "${request#*:}" ]]; then
    echo "test-install: dpc $version: expected ${request#*:} from both" >&2
    exit 1
  fi
done

# A program compiled against 0.6.0's, 0.7.0's and 0.8.0's dpc.h (and their dpc_version.h,
# generated as CMake did) runs against this library and prints what the same program compiled
# against the installed dpc.h prints (tests/install/layout_client.c checks its own results).
# tests/install/dpc-X.Y.Z holds that release's headers as CMake installed them.
for build in "dpc-0.6.0:$root/tests/install/dpc-0.6.0" "dpc-0.7.0:$root/tests/install/dpc-0.7.0" \
             "dpc-0.8.0:$root/tests/install/dpc-0.8.0" "current:$prefix/include"; do
  name=${build%%:*} header=${build#*:}
  cc -std=c99 -Wall -Werror -o "$work/layout_client-$name" tests/install/layout_client.c \
    -I"$header" -L"$libdir" -ldpc -lm
  "$work/layout_client-$name" >"$work/layout_client-$name.txt"
  cat "$work/layout_client-$name.txt"
done
diff "$work/layout_client-dpc-0.6.0.txt" "$work/layout_client-current.txt"
diff "$work/layout_client-dpc-0.7.0.txt" "$work/layout_client-current.txt"
diff "$work/layout_client-dpc-0.8.0.txt" "$work/layout_client-current.txt"
if [[ -d $libdir/lv2/dpc.lv2 ]]; then
  # The installed bundle finds libdpc.so through its RPATH, not LD_LIBRARY_PATH.
  env -u LD_LIBRARY_PATH /usr/bin/python3 tests/lv2/lv2_test.py "$libdir/lv2"
  # The README's LV2_PATH line adds the bundle to what hosts find without hiding the plugins
  # they found before: lv2ls lists lilv's default set plus dpc's.
  line=$(grep '^export LV2_PATH=' README.md)
  before=$(env -u LV2_PATH lv2ls | sort)
  after=$(env -u LV2_PATH bash -c "${line/\$HOME\/dpc\/lib/$libdir}; lv2ls" | sort)
  if [[ -n $(comm -23 <(echo "$before") <(echo "$after")) ]] || ! grep -q '^urn:dpc:lv2:room$' <<<"$after"; then
    echo "test-install: README's LV2_PATH line hides plugins or misses dpc's" >&2
    exit 1
  fi
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
