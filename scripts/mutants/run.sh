#!/usr/bin/env bash
# Mutation check: applies each scripts/mutants/*.patch (a realistic, user-visible one-line bug)
# to a scratch git worktree of this checkout's HEAD, rebuilds incrementally, runs the tests and
# reports whether they fail (the mutant is caught) or pass (MISSED: the suite does not see the bug).
#
#   scripts/mutants/run.sh [--quick-suite] [--no-baseline] [--keep] [--table FILE] [PATCH...]
#
#   PATCH...        patches to run (names or paths; default: every scripts/mutants/*.patch)
#   (default)       each patch's own tests: its "Tests: REGEX" line (ctest -R), building only its
#                   "Build: TARGET..." line's targets (the test binaries and programs those
#                   tests run)
#   --quick-suite   the whole quick suite for every patch (ctest -LE full, everything built)
#   --no-baseline   skip the clean run first (by default the selected tests run once on the
#                   unpatched tree; a test that fails there does not count as catching a mutant)
#   --keep          keep the scratch worktree and its build for the next run (faster)
#   --table FILE    also write the table as Markdown to FILE
#
# Environment: DPC_MUTANTS_WORK (scratch folder; default: mutants-scratch next to the checkout),
# DPC_MUTANTS_JOBS (build and ctest jobs, default 2), DPC_MUTANTS_NICE (default 15),
# DPC_MUTANTS_TIMEOUT (ctest's timeout for tests without their own, default 300 s).
# Exit status: 0 when every mutant was caught, 1 when one was missed or did not build, 2 on a
# usage or setup error. Not run in CI (minutes per mutant); docs/hardening.md "Mutation check".
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
repo=$(git -C "$here" rev-parse --show-toplevel)
base=$(git -C "$repo" rev-parse HEAD)
work=${DPC_MUTANTS_WORK:-$(dirname "$repo")/mutants-scratch}
jobs=${DPC_MUTANTS_JOBS:-2}
niceness=${DPC_MUTANTS_NICE:-15}
timeout=${DPC_MUTANTS_TIMEOUT:-300}
quick=0 baseline=1 keep=0 table_out=""
patches=()
while (($#)); do
  case "$1" in
    --quick-suite) quick=1 ;;
    --no-baseline) baseline=0 ;;
    --keep) keep=1 ;;
    --table) table_out=$(realpath -m "$2"); shift ;;
    -h|--help) sed -n '2,24p' "$0"; exit 0 ;;
    -*) echo "run.sh: unknown option $1" >&2; exit 2 ;;
    *) p=$1
       [[ -f $p ]] || p=$here/${1%.patch}.patch
       [[ -f $p ]] || { echo "run.sh: no patch $1" >&2; exit 2; }
       patches+=("$(realpath "$p")") ;;
  esac
  shift
done
((${#patches[@]})) || patches=("$here"/*.patch)

# A patch's "Tests:" and "Build:" lines (before its diff).
field() { sed -n '/^diff --git/q; s/^'"$1"': *//p' "$2" | head -1; }
for p in "${patches[@]}"; do
  if ((!quick)) && [[ -z $(field Tests "$p") ]]; then
    echo "run.sh: $(basename "$p") has no 'Tests:' line (or use --quick-suite)" >&2
    exit 2
  fi
done

tree=$work/tree
build=$tree/build  # inside the tree: ccache (CCACHE_BASEDIR) sees the same relative paths as ./build
mkdir -p "$work"
if git -C "$tree" rev-parse --is-inside-work-tree >/dev/null 2>&1; then
  git -C "$tree" reset -q --hard
  git -C "$tree" checkout -q --detach "$base"
else
  git -C "$repo" worktree add -q --detach "$tree" "$base"
fi

cleanup() {
  git -C "$tree" reset -q --hard "$base" 2>/dev/null || true
  if ((!keep)); then
    git -C "$repo" worktree remove --force "$tree" 2>/dev/null || true
    rm -rf "$tree"
  fi
}
trap cleanup EXIT

# As scripts/build.sh: paths relative to the checkout, so other checkouts' ccache entries hit.
export CCACHE_BASEDIR=${CCACHE_BASEDIR:-$tree} CCACHE_NOHASHDIR=true
run() { nice -n "$niceness" "$@"; }
if [[ ! -f $build/CMakeCache.txt ]]; then
  generator=() launcher=()
  command -v ninja >/dev/null && generator=(-G Ninja)
  command -v ccache >/dev/null &&
    launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
  run cmake -S "$tree" -B "$build" "${generator[@]}" "${launcher[@]}" \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo >"$work/configure.log" 2>&1 ||
    { echo "run.sh: configure failed, see $work/configure.log" >&2; exit 2; }
fi

# build TARGET... (none: everything); its output goes to $1's log.
build_targets() {
  local log=$1; shift
  if (($#)); then
    run cmake --build "$build" -j"$jobs" --target "$@" >"$log" 2>&1
  else
    run cmake --build "$build" -j"$jobs" >"$log" 2>&1
  fi
}

# tests REGEX LOG: runs ctest (REGEX empty: the quick suite); sets ran and failed (names).
tests() {
  local regex=$1 log=$2 sel=(-LE full)
  [[ -n $regex ]] && sel=(-R "$regex" -LE full)
  rm -f "$build/Testing/Temporary/LastTestsFailed.log"
  (cd "$build" && run ctest "${sel[@]}" -j"$jobs" --timeout "$timeout" --output-on-failure) \
    >"$log" 2>&1 || true
  ran=$(sed -n 's/.* tests failed out of \([0-9]*\)$/\1/p' "$log" | tail -1)
  [[ -n $ran ]] || ran=0
  failed=()
  if [[ -f $build/Testing/Temporary/LastTestsFailed.log ]]; then
    mapfile -t failed < <(cut -d: -f2- "$build/Testing/Temporary/LastTestsFailed.log")
  fi
}

targets_of() { ((quick)) || field Build "$1"; }
regex_of() { ((quick)) || field Tests "$1"; }

declare -A broken=()  # tests failing on the clean tree
if ((baseline)); then
  all_targets=() all_regex=()
  for p in "${patches[@]}"; do
    read -ra t <<<"$(targets_of "$p")"
    all_targets+=("${t[@]}")
    all_regex+=("$(regex_of "$p")")
  done
  # Joined without groups: CMake's regular expressions allow few parentheses (Tests: lines
  # use none but inside one alternative).
  regex=""
  ((quick)) || regex=$(printf '%s\n' "${all_regex[@]}" | sort -u | paste -sd'|')
  read -ra uniq <<<"$(printf '%s\n' "${all_targets[@]}" | sort -u | tr '\n' ' ')"
  echo "baseline: building ${uniq[*]:-everything} on $(git -C "$repo" rev-parse --short HEAD)" >&2
  start=$SECONDS
  build_targets "$work/baseline-build.log" "${uniq[@]}" ||
    { echo "run.sh: the clean tree does not build, see $work/baseline-build.log" >&2; exit 2; }
  tests "$regex" "$work/baseline-tests.log"
  if ((ran == 0)); then
    echo "run.sh: no test ran on the clean tree, see $work/baseline-tests.log" >&2
    exit 2
  fi
  for t in "${failed[@]}"; do broken[$t]=1; done
  echo "baseline: $ran tests, ${#failed[@]} failing on the clean tree$( ((${#failed[@]})) &&
    printf ' (not counted): %s' "${failed[*]}") ($((SECONDS - start)) s)" >&2
fi

rows=() missed=0
for p in "${patches[@]}"; do
  name=$(basename "$p" .patch)
  start=$SECONDS
  git -C "$tree" reset -q --hard "$base"
  if ! git -C "$tree" apply "$p" 2>"$work/$name.apply.log"; then
    rows+=("$name|0|-|NO-APPLY|$((SECONDS - start))"); missed=1; continue
  fi
  read -ra t <<<"$(targets_of "$p")"
  echo "$name: building ${t[*]:-everything}" >&2
  if ! build_targets "$work/$name.build.log" "${t[@]}"; then
    rows+=("$name|0|-|NO-BUILD|$((SECONDS - start))"); missed=1; continue
  fi
  tests "$(regex_of "$p")" "$work/$name.tests.log"
  caught_by=()
  for f in "${failed[@]}"; do [[ -n ${broken[$f]:-} ]] || caught_by+=("$f"); done
  if ((ran == 0)); then
    result=NO-TESTS; missed=1
  elif ((${#caught_by[@]})); then
    result=caught
  else
    result=MISSED; missed=1
  fi
  by=$( ((${#caught_by[@]})) && printf '%s; ' "${caught_by[@]}" | sed 's/; $//' || echo -)
  rows+=("$name|$ran|$by|$result|$((SECONDS - start))")
  echo "$name: $result ($ran tests, $((SECONDS - start)) s)" >&2
done

mode="each patch's Tests: line"
((quick)) && mode="the quick suite (ctest -LE full)"
echo
echo "Mutation check of $(git -C "$repo" rev-parse --short HEAD), tests: $mode"
printf '%-34s %5s  %-8s %7s  %s\n' patch tests result seconds "failing tests (new)"
for r in "${rows[@]}"; do
  IFS='|' read -r name ran by result secs <<<"$r"
  printf '%-34s %5s  %-8s %7s  %s\n' "$name" "$ran" "$result" "$secs" "$by"
done
if [[ -n $table_out ]]; then
  {
    echo "| patch | tests run | result | seconds | failing tests (new) |"
    echo "|---|---|---|---|---|"
    for r in "${rows[@]}"; do
      IFS='|' read -r name ran by result secs <<<"$r"
      echo "| $name | $ran | $result | $secs | $by |"
    done
  } >"$table_out"
fi
exit "$missed"
