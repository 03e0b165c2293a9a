#!/usr/bin/env bash
# AddressSanitizer + UndefinedBehaviorSanitizer run: configures build-asan with -DDPC_ASAN=ON
# (-O1), builds dpc-demo, dpc-analyze and the test binaries that exercise input handling, the
# engine and the runtime, and runs their ctest cases there (device tests jack|live and the LV2
# bundle, which an uninstrumented host dlopens, excluded;
# the heap-counting tests/rt binaries are not built: ASan replaces malloc). The bad-input suite
# runs against the sanitized dpc-demo. UBSan errors abort (no recovery); LeakSanitizer is on.
#
#   scripts/asan.sh                       # exit status: ctest's
#   ASAN_TARGETS=all scripts/asan.sh      # every test binary (the whole ctest; longer)
#   ASAN_TESTS='wav_io|bad_input' scripts/asan.sh    # only tests matching a regex
#
# Cost: see docs/hardening.md ("Sanitizers and fuzzing").
set -euo pipefail
cd "$(dirname "$0")/.."

build=${BUILD_DIR:-build-asan}
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
start=$(date +%s)
cmake -S . -B "$build" -G Ninja -DDPC_ASAN=ON -DCMAKE_BUILD_TYPE=RelWithDebInfo "${launcher[@]}" >/dev/null
# The default set (kept small for CI time): loaders and writers, the engine's tracing and
# cache, the offline pipeline, the work estimate, the limiter, and the apps (the whole
# bad-input suite). The threaded hand-over runs under TSan (scripts/tsan.sh).
# ASAN_TARGETS=all: every test binary.
targets=(${ASAN_TARGETS:-dpc-demo dpc-analyze scene_test wav_io_test propagation_test
  path_cache_test dpc_demo_test analyze_names_test workload_test limiter_test})
if [[ "${targets[*]}" == all ]]; then targets=(all); fi
cmake --build "$build" -j"${JOBS:-$(nproc 2>/dev/null || echo 2)}" --target "${targets[@]}"
built=$(date +%s)

export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0:exitcode=86:${ASAN_OPTIONS:-}"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1:exitcode=87:${UBSAN_OPTIONS:-}"
# LeakSanitizer: only the system libraries' own one-time allocations (see the file).
export LSAN_OPTIONS="suppressions=$PWD/tests/lsan.supp:${LSAN_OPTIONS:-}"
set +e
(cd "$build" && ctest --output-on-failure -j"${JOBS:-$(nproc 2>/dev/null || echo 2)}" --timeout 900 \
   -E 'jack|live|lv2|_NOT_BUILT' ${ASAN_TESTS:+-R "$ASAN_TESTS"})
status=$?
set -e
end=$(date +%s)
echo "asan.sh: build $((built - start)) s, tests $((end - built)) s, status $status"
exit "$status"
