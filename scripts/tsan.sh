#!/usr/bin/env bash
# ThreadSanitizer run of the audio side's IR hand-over (tests/rt/queue_tsan_test.cpp):
# configures build-tsan with -DDPC_TSAN=ON (-fsanitize=thread), builds only that test and
# runs it. The interposing-allocator tests (tests/rt/*_test.cpp other than *_tsan_test) are
# not built under TSan, which replaces malloc itself.
#
#   scripts/tsan.sh            # exit status: the test's (TSan reports fail it: halt_on_error)
#
# Cost (measured on 2 cores): first configure + build about 65 s (dpc_runtime and its
# libraries are compiled with -fsanitize=thread), rebuilds after a change seconds; the test
# itself 1-2 s (about 4,000-15,000 blocks and 200+ IR swaps under TSan).
set -euo pipefail
cd "$(dirname "$0")/.."

build=${BUILD_DIR:-build-tsan}
start=$(date +%s)
source scripts/ccache-launcher.sh
cmake -S . -B "$build" -G Ninja -DDPC_TSAN=ON -DCMAKE_BUILD_TYPE=RelWithDebInfo "${launcher[@]}" >/dev/null
cmake --build "$build" --target queue_tsan_test pipeline_tsan_test -j"${JOBS:-2}"
built=$(date +%s)

# halt_on_error: the first race fails the run; second_deadlock_stack for lock reports.
set +e
TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1 ${TSAN_OPTIONS:-}" \
  "$build/tests/queue_tsan_test" "[tsan]"
status=$?
if ((status == 0)); then
  # tests/rt/tsan.supp: uninstrumented libtbb's internals only (see the file).
  TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1 suppressions=$PWD/tests/rt/tsan.supp ${TSAN_OPTIONS:-}" \
    "$build/tests/pipeline_tsan_test" "[tsan]"
  status=$?
fi
set -e
end=$(date +%s)
echo "tsan.sh: build $((built - start)) s, test $((end - built)) s, status $status"
exit "$status"
