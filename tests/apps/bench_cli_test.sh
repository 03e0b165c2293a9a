#!/usr/bin/env bash
# dpc-bench's bad input: each flag out of range (or NaN, which CLI11's own range check lets
# through) is refused in one line naming the flag, exit status 1, before any work. Before,
# --reference-frames 0 crashed (SIGSEGV) and --frames 0, --threads -1, --walk-speed nan and
# --frame-rate nan gave exit 0 with null or defaulted reports.
# Usage: bench_cli_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
bench="$1/bench/dpc-bench"
scene="$2/scenes/shoebox.json"
err=$(mktemp)
trap 'rm -f "$err"' EXIT
fails=0
refused() {  # refused FLAG ARGS...: exit 1, one line "dpc-bench: command line: FLAG: ..."
  local flag=$1; shift
  local status=0
  timeout 60 "$bench" "$@" >/dev/null 2>"$err" || status=$?
  if [[ $status != 1 || $(wc -l <"$err") != 1 ]] || ! grep -q -- "^dpc-bench: command line: $flag" "$err"; then
    echo "FAIL: dpc-bench $*: status $status, stderr: $(cat "$err")"
    fails=$((fails + 1))
  else
    echo "ok    dpc-bench $*: $(cat "$err")"
  fi
}
refused --reference-frames noise "$scene" --frames 1 --rays 64 --reference-frames 0
refused --frames propagation "$scene" --frames 0
refused --threads propagation "$scene" --threads -1
refused --rays propagation "$scene" --rays 0
refused --walk-speed noise "$scene" --walk-speed nan
refused --pt-multipliers noise "$scene" --pt-multipliers 0
refused --warmup noise "$scene" --warmup -1
refused --frame-rate live "$scene" --frame-rate nan
refused --duration live "$scene" --duration -1
refused --tau propagation "$scene" --tau inf
refused "A subcommand is required"
((fails == 0)) || exit 1
echo "all dpc-bench refusals hold"
