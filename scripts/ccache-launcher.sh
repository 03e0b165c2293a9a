# Sourced by the build scripts (build.sh, asan.sh, tsan.sh, fuzz.sh): sets `launcher`, the
# CMake flags that compile through ccache when it is installed. ccache reads paths relative to
# the checkout and leaves the working directory out of the hash (-g would put it in), so
# checkouts at different paths (CI's fresh clone, git worktrees, the venv install test's copy
# of the sources) compile to the same cache entries.
export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$PWD}" CCACHE_NOHASHDIR=true
launcher=()
if command -v ccache >/dev/null; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
fi
