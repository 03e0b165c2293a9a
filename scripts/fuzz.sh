#!/usr/bin/env bash
# libFuzzer runs of the scene JSON loader, the OBJ reader, the WAV reader, the C API's
# dpc_engine_create_from_data, the bake file's reader and the glTF/GLB level reader (fuzz/): configures build-fuzz with
# clang and -DDPC_FUZZ=ON (ASan+UBSan+coverage), builds the six targets and
# runs each for SECONDS (default 20) from its seed corpus in fuzz/corpus/<target>. New inputs
# go to a scratch corpus (build-fuzz/corpus/<target>), never into the repository; a crash
# leaves its reproducer in build-fuzz/ and fails the run.
#
#   scripts/fuzz.sh           # CI smoke run: 20 s per target
#   scripts/fuzz.sh 3600      # an hour per target
#   build-fuzz/fuzz/scene_fuzzer CRASH_FILE    # replay one reproducer
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-20}
if ! command -v clang++ >/dev/null; then
  echo "fuzz.sh: clang++ not found (scripts/install-deps.sh installs clang); skipped" >&2
  # In CI the fuzzers must run: a missing compiler is a failure there, not a skip.
  [[ ${CI:-} == true ]] && exit 1
  exit 0
fi
build=${BUILD_DIR:-build-fuzz}
source scripts/ccache-launcher.sh
start=$(date +%s)
CC=clang CXX=clang++ cmake -S . -B "$build" -G Ninja -DDPC_FUZZ=ON -DDPC_BUILD_TESTS=OFF \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo "${launcher[@]}" >/dev/null
cmake --build "$build" --target scene_fuzzer obj_fuzzer wav_fuzzer c_api_fuzzer bake_fuzzer gltf_fuzzer -j"${JOBS:-$(nproc 2>/dev/null || echo 2)}"
built=$(date +%s)
export ASAN_OPTIONS="detect_leaks=1:${ASAN_OPTIONS:-}"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1:${UBSAN_OPTIONS:-}"
export LSAN_OPTIONS="suppressions=$PWD/tests/lsan.supp:${LSAN_OPTIONS:-}"
status=0
for t in scene obj wav c_api bake gltf; do
  mkdir -p "$build/corpus/$t"
  # -rss_limit_mb: the loaders bound their inputs, so more than 2 GB is a finding too.
  # -timeout (per input): 30 s, a hang; an engine with binaural decoding is created in up to
  # 8 s here (HRTF load, MagLS fit, under the sanitizers and coverage), 12 s on a loaded machine.
  if ! (cd "$build" && "fuzz/${t}_fuzzer" -max_total_time="$seconds" -timeout=30 -rss_limit_mb=2048 \
          -max_len=65536 -print_final_stats=1 "corpus/$t" "$PWD/../fuzz/corpus/$t" 2>"$t.log"); then
    echo "fuzz.sh: ${t}_fuzzer found a problem:" >&2
    tail -40 "$build/$t.log" >&2
    status=1
  fi
  grep -E "stat::number_of_executed_units|stat::peak_rss_mb" "$build/$t.log" | sed "s/^/${t}: /" || true
done
end=$(date +%s)
echo "fuzz.sh: build $((built - start)) s, fuzzing $((end - built)) s, status $status"
exit "$status"
