#!/usr/bin/env bash
# Runs the dpc-bench sweeps behind docs/performance.md, one JSON file per run in out/bench/,
# strictly one benchmark at a time. Then: /usr/bin/python3 scripts/plot_bench.py
#
# Usage: scripts/bench_sweep.sh [--no-build | --bench PATH] [--skip-existing] [--frames F]
#                               [--only SECTIONS] [--max-wait S]
#   --no-build       use the existing build/bench/dpc-bench
#   --bench PATH     use this dpc-bench binary (e.g. one built from a clean checkout)
#   --skip-existing  keep JSON files that are already there (re-plot after a partial sweep)
#   --frames F       frames per propagation run (default 10)
#   --only SECTIONS  comma-separated subset of: rays,order,triangles,cache,noise,walk
#   --max-wait S     seconds to wait for an idle machine before starting (default 180)
#   --run-wait S     seconds to wait before each timed (propagation) run while other processes
#                    use more than 0.25 core (default 60; noise results do not depend on speed)
#
# Sweeps (see docs/performance.md):
#   rays       prop-{shoebox,hall}-rays-N.json: N = 512..16384, max order 200, 2 threads,
#              roulette; plus -rays-4096-noroulette and -rays-4096-t1 (1 thread)
#   order      prop-hall-order-D.json: 4096 rays, D = 10..400, --no-roulette, 2 threads
#   triangles  prop-hall-tri-kK-tT.json: hall subdivided 4^K (K = 0..3, ~16k..1M triangles,
#              written to out/scenes/ by scenes/generate_hall.py), 4096 rays, order 200,
#              --no-roulette, T = 1, 2 threads (bare Embree yardstick in the same JSON)
#   cache      prop-hall-cache.json: 4096 rays x order 200, tau 1 s, 150 frames (cache size
#              once EMA entries have had time to age out)
#   noise      noise-shoebox-static-rays-N.json: N = 1024..8192, static listener, reference =
#              2^20 rays (>= 128x the run's rays)
#   walk       noise-shoebox-walk.json: 4096 rays, listener walking at 1.4 m/s
#
# The binary is copied to out/bench/bin/ first, so a rebuild of ./build during the sweep
# (other work on the same machine) cannot mix two versions in one sweep.
#
# Machine load: before the first run the script waits (up to --max-wait s) for a 1-minute load
# average <= 0.5. The load average includes the sweep's own previous run, so before each timed
# run it instead samples /proc/stat for 2 s and waits (up to --run-wait s) while other processes
# use more than 0.25 core. For every run it appends to out/bench/sweep-log.tsv the load average
# and the other processes' CPU use before the run, and the CPU time other processes used during
# it (cores: /proc/stat busy time minus the benchmark's own user+sys time), so a reader knows
# whether a number was taken on a busy machine.
set -euo pipefail
cd "$(dirname "$0")/.."

build=1 bench_src=build/bench/dpc-bench skip=0 frames=10 only="rays,order,triangles,cache,noise,walk" max_wait=180 run_wait=60
while (($#)); do
  case "$1" in
    --no-build) build=0 ;;
    --bench) build=0; bench_src="$2"; shift ;;
    --skip-existing) skip=1 ;;
    --frames) frames="$2"; shift ;;
    --only) only="$2"; shift ;;
    --max-wait) max_wait="$2"; shift ;;
    --run-wait) run_wait="$2"; shift ;;
    -h|--help) sed -n '2,/^set -euo/p' "$0" | sed '$d' | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "bench_sweep.sh: unknown option $1" >&2; exit 2 ;;
  esac
  shift
done
want() { [[ ",$only," == *",$1,"* ]]; }

PY=/usr/bin/python3
OUT=out/bench
LOG=$OUT/sweep-log.tsv
mkdir -p "$OUT/logs" out/scenes
if ((build)); then scripts/build.sh dpc-bench; fi
[[ -x $bench_src ]] || { echo "bench_sweep.sh: $bench_src not built" >&2; exit 1; }
mkdir -p "$OUT/bin"
BENCH=$OUT/bin/dpc-bench
cp "$bench_src" "$BENCH"
[[ -f $LOG ]] || printf 'file\tstarted\tload1_before\tother_cores_before\twaited_s\twall_s\tbench_cpu_s\tother_cpu_cores\n' >"$LOG"

load1() { cut -d' ' -f1 /proc/loadavg; }
busy_jiffies() { awk '/^cpu /{print $2+$3+$4+$7+$8}' /proc/stat; }  # user nice system irq softirq
hz=$(getconf CLK_TCK)
# CPU cores in use by all processes over the next 2 s (the sweep runs nothing meanwhile).
others_cores() {
  local j0 j1
  j0=$(busy_jiffies); sleep 2; j1=$(busy_jiffies)
  awk -v a="$j0" -v b="$j1" -v hz="$hz" 'BEGIN{printf "%.2f", (b - a) / hz / 2}'
}

waited=0
while awk -v l="$(load1)" 'BEGIN{exit !(l > 0.5)}' && ((waited < max_wait)); do
  ((waited == 0)) && echo "load average $(load1) > 0.5: waiting up to ${max_wait}s for an idle machine" >&2
  sleep 15; waited=$((waited + 15))
done
echo "starting at load average $(load1) (waited ${waited}s)" >&2
sweep_start=$(date +%s)
printf 'sweep (%s) started %s with %s (%s), %s, %s cores\n' "$only" "$(date +%FT%T)" \
  "$bench_src" "$(stat -c %y "$bench_src" | cut -d. -f1)" \
  "worktree $(git describe --always --dirty 2>/dev/null || echo unknown)" "$(nproc)" >>"$OUT/sweep-summary.txt"

total_waited=$waited
# run NAME dpc-bench-args... : one benchmark, JSON to out/bench/NAME.json, log line appended.
# Timed runs (propagation) first wait for the other processes to go quiet.
run() {
  local name=$1; shift
  local json=$OUT/$name.json
  if ((skip)) && [[ -s $json ]]; then echo "skip $name (exists)" >&2; return; fi
  local l0 j0 t0 j1 t1 oc w=0
  oc=$(others_cores)
  if [[ $1 == propagation ]]; then
    while awk -v o="$oc" 'BEGIN{exit !(o > 0.25)}' && ((w < run_wait)); do
      sleep 3; w=$((w + 5)); oc=$(others_cores)
    done
  fi
  total_waited=$((total_waited + w))
  l0=$(load1); j0=$(busy_jiffies); t0=$(date +%s.%N)
  echo "[$(date +%T)] $name: dpc-bench $* (load $l0, others $oc cores, waited ${w}s)" >&2
  /usr/bin/time -f '%U %S' -o "$OUT/logs/$name.time" "$BENCH" "$@" >"$json.tmp" 2>"$OUT/logs/$name.err"
  t1=$(date +%s.%N); j1=$(busy_jiffies)
  mv "$json.tmp" "$json"
  read -r u s <"$OUT/logs/$name.time"
  awk -v f="$name.json" -v st="$(date -d @"${t0%.*}" +%FT%T)" -v l="$l0" -v t0="$t0" -v t1="$t1" \
      -v j0="$j0" -v j1="$j1" -v hz="$hz" -v u="$u" -v s="$s" -v oc="$oc" -v wt="$w" 'BEGIN{
        w = t1 - t0; other = ((j1 - j0) / hz - u - s) / w; if (other < 0) other = 0;
        printf "%s\t%s\t%s\t%s\t%d\t%.1f\t%.1f\t%.2f\n", f, st, l, oc, wt, w, u + s, other }' >>"$LOG"
  tail -n1 "$LOG" | awk -F'\t' '{printf "    %.1f s, other processes %.2f cores during the run\n", $6, $8}' >&2
}

if want rays; then
  for scene in shoebox hall; do
    for rays in 512 1024 2048 4096 8192 16384; do
      run "prop-$scene-rays-$rays" propagation "scenes/$scene.json" --rays "$rays" \
        --max-order 200 --threads 2 --frames "$frames"
    done
    run "prop-$scene-rays-4096-noroulette" propagation "scenes/$scene.json" --rays 4096 \
      --max-order 200 --threads 2 --frames "$frames" --no-roulette
    run "prop-$scene-rays-4096-t1" propagation "scenes/$scene.json" --rays 4096 \
      --max-order 200 --threads 1 --frames "$frames"
  done
fi

if want order; then
  for order in 10 25 50 100 200 400; do
    run "prop-hall-order-$order" propagation scenes/hall.json --rays 4096 --max-order "$order" \
      --threads 2 --frames "$frames" --no-roulette
  done
fi

if want triangles; then
  for k in 0 1 2 3; do
    scene=scenes/hall.json
    if ((k > 0)); then
      scene=out/scenes/hall-k$k.json
      [[ -s $scene && -s out/scenes/hall-k$k.obj ]] ||
        $PY scenes/generate_hall.py "out/scenes/hall-k$k.obj" --subdivide "$k" --scene "$scene"
    fi
    for threads in 1 2; do
      run "prop-hall-tri-k$k-t$threads" propagation "$scene" --rays 4096 --max-order 200 \
        --threads "$threads" --frames "$frames" --no-roulette
    done
  done
fi

if want cache; then
  run prop-hall-cache propagation scenes/hall.json --rays 4096 --max-order 200 --tau 1 \
    --threads 2 --frames 150
fi

if want noise; then
  # Reference: 2^20 rays for every run (>= 128x the run's rays). Path-tracing multipliers:
  # enough to bracket the DPC's error where it is cheap; 4096 rays is the headline run.
  declare -A mult=([1024]="1 2 4 8 16 32" [2048]="1 2 4 8 16 32" [4096]="1 2 4 8 16 32"
                   [8192]="1 2 4 8")
  for rays in 1024 2048 4096 8192; do
    nf=20; ((rays == 4096)) && nf=30
    # shellcheck disable=SC2086
    run "noise-shoebox-static-rays-$rays" noise scenes/shoebox.json --rays "$rays" \
      --frames "$nf" --reference-frames $((1048576 / rays)) --threads 2 \
      --pt-multipliers ${mult[$rays]}
  done
fi

if want walk; then
  run noise-shoebox-walk noise scenes/shoebox.json --rays 4096 --frames 20 --walk-speed 1.4 \
    --reference-frames 64 --threads 2 --pt-multipliers 1 2 4 8 16
fi

elapsed=$(($(date +%s) - sweep_start))
printf 'sweep (%s) finished %s: %d s (%d min %d s) from the first run, of which %d s waiting for\n  other processes (plus %d s before the first run)\n' \
  "$only" "$(date +%FT%T)" "$elapsed" $((elapsed / 60)) $((elapsed % 60)) \
  $((total_waited - waited)) "$waited" |
  tee -a "$OUT/sweep-summary.txt" >&2
echo "plot: $PY scripts/plot_bench.py" >&2
