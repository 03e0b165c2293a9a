#!/usr/bin/env bash
# Configures and builds dpc into ./build (RelWithDebInfo). Usage: scripts/build.sh [targets...]
set -euo pipefail
cd "$(dirname "$0")/.."
generator=()
command -v ninja >/dev/null && generator=(-G Ninja)
# ccache, when installed, lets several checkouts (git worktrees) share compiled objects.
# ccache reads paths relative to the checkout and leaves the working directory out of the
# hash (-g would put it in), so a copy of the sources inside the checkout (the venv install
# test's) compiles to the same cache entries.
export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$PWD}" CCACHE_NOHASHDIR=true
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
if [[ ! -f build/CMakeCache.txt ]]; then
  cmake -S . -B build "${generator[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo "${launcher[@]}" >/dev/null
fi
jobs=$(nproc 2>/dev/null || echo 2)
if (($#)); then
  cmake --build build -j"$jobs" --target "$@"
else
  cmake --build build -j"$jobs"
fi
