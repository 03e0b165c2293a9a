#!/usr/bin/env bash
# dpc-bake end to end: a bake interrupted (SIGTERM, SIGHUP, SIGINT: exit 128 + n) and resumed
# equals a clean one; with Open MPI
# (when mpirun is installed), -np 1 and -np 2 write the same datasets as the single-process run,
# and a rank killed mid-bake ends the job non-zero with a file --resume completes to the same
# data; bad input gets one line naming file and field, exit 1, no file created or changed.
# Datasets compared with h5diff (Debian hdf5-tools). Usage: bake_cli_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
bake="$1/apps/dpc-bake"
scene="$2/scenes/shoebox.json"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
fail() { echo "FAIL: $*" >&2; exit 1; }
quick=(--spacing 2 --rays 500 --frames 4 --threads 1)
slow=(--spacing 1 --rays 1000 --frames 4 --threads 1)
complete() { h5dump -a /complete "$1" | grep -q '(0): 1'; }

# Waits until the run writing stderr to $1 has committed a probe (a progress line), then sends
# signal $3 to pid $2.
kill_after_first_probe() {
  for _ in $(seq 1 600); do
    grep -q 'probes/s' "$1" 2>/dev/null && break
    sleep 0.1
  done
  kill "-$3" "$2"
}

echo "== clean and interrupted + resumed bakes are identical"
"$bake" "$scene" --out clean.h5 "${slow[@]}" --quiet
complete clean.h5 || fail "clean bake not marked complete"
# Each stop signal n: one line naming it, exit 128 + n, the file incomplete; cut.h5 (SIGTERM)
# resumed equals the clean bake.
for sig in TERM HUP INT; do
  "$bake" "$scene" --out "cut$sig.h5" "${slow[@]}" 2>"cut$sig.err" & pid=$!
  kill_after_first_probe "cut$sig.err" $pid $sig
  status=0; wait $pid || status=$?
  [[ $status == $((128 + $(kill -l $sig))) ]] || fail "SIG$sig: exit status $status"
  [[ $(grep -c "cut$sig.h5: interrupted by SIG$sig with .* dpc-bake --resume cut$sig.h5" \
      "cut$sig.err") == 1 ]] || fail "no SIG$sig interruption line: $(cat "cut$sig.err")"
  complete "cut$sig.h5" && fail "bake interrupted by SIG$sig marked complete"
done
mv cutTERM.h5 cut.h5
"$bake" --resume cut.h5 --quiet
h5diff clean.h5 cut.h5 || fail "resumed bake differs from the clean one"

echo "== the map of a complete bake, and the h5py example reading it"
"$bake" --resume clean.h5 --map map.csv --quiet
# 70 probes x 1 source x (9 rows x 7 parameters + STI) rows and the header.
[[ $(wc -l <map.csv) == $((70 * 64 + 1)) ]] || fail "map.csv has $(wc -l <map.csv) lines"
if /usr/bin/python3 -c 'import h5py' 2>/dev/null; then
  # Read whole, then searched (grep -q on the pipe could close it before the script ends).
  /usr/bin/python3 "$2/examples/python/read_bake.py" clean.h5 5 1.6 3.5 >read.txt ||
    fail "read_bake.py exited non-zero"
  grep -q STI read.txt && grep -q 'energy flow' read.txt || fail "read_bake.py: $(cat read.txt)"
fi

echo "== a box of probes: a 3-D lattice, its layout recorded"
# The shoebox is 10 x 3 x 7 m (y up): 4 x 2 x 3 points at 1 m in this box.
"$bake" "$scene" --out box.h5 --spacing 1 --box 3 0.5 2 7 2.5 5 --rays 300 --frames 4 \
  --threads 1 --quiet
complete box.h5 || fail "box bake not marked complete"
h5dump -a /probe_layout box.h5 | grep -q '"box 3 0.5 2 7 2.5 5"' || fail "probe_layout"
h5dump -a /grid_candidates box.h5 | grep -q '(0): 24' || fail "box candidates"

echo "== bad input: one line, exit 1, nothing created or changed"
listing() { find . -maxdepth 1 -type f ! -name err.txt -printf '%f %s %T@\n' | sort; }
expect_refusal() {  # expect_refusal WORD ARGS...: exit 1, one line containing WORD
  local word=$1; shift
  local before; before=$(listing)
  if "$bake" "$@" 2>err.txt; then fail "accepted: $*"; fi
  [[ $(wc -l <err.txt) == 1 ]] || fail "not one line for $*: $(cat err.txt)"
  grep -q -- "$word" err.txt || fail "line does not name $word: $(cat err.txt)"
  [[ $(listing) == "$before" ]] || fail "files changed by $*"
}
cp clean.h5 keep.h5
# An existing --out or --map nobody may write (mode 444, refused for root too), and empty values.
chmod 444 keep.h5
expect_refusal "--out: 'keep.h5': cannot write: the file is read-only" "$scene" --out keep.h5 \
  --spacing 2
expect_refusal "--map: 'keep.h5': cannot write: the file is read-only" --resume clean.h5 \
  --map keep.h5
chmod 644 keep.h5
expect_refusal "command line: --map: is empty" "$scene" --out new.h5 --spacing 2 --map ""
expect_refusal "command line: --out: is empty" "$scene" --out "" --spacing 2
expect_refusal "command line: --spacing: is empty" "$scene" --out new.h5 --spacing ""
expect_refusal --spacing "$scene" --out keep.h5 --spacing 0
expect_refusal --spacing "$scene" --out keep.h5 --spacing -1
expect_refusal shoebox.json "$scene" --out keep.h5 --spacing 50
expect_refusal --height "$scene" --out keep.h5 --spacing 1 --height 9
expect_refusal --box "$scene" --out keep.h5 --spacing 1 --box 3 2 2 3 2.5 5
expect_refusal --box "$scene" --out keep.h5 --spacing 1 --box 3 2 2 7 2.5
expect_refusal --box "$scene" --out keep.h5 --spacing 1 --box 3 0.5 2 7 2.5 5 --height 1
expect_refusal --box "$scene" --out keep.h5 --spacing 1 --box 30 20 20 40 25 25
printf '5 1.6 3.5\n5 1.6\n' >list.txt
expect_refusal "list.txt: line 2" "$scene" --out keep.h5 --probes list.txt
head -c 3000 clean.h5 >truncated.h5
expect_refusal truncated.h5 --resume truncated.h5
cp cut.h5 other.h5
expect_refusal mesh_hash --resume other.h5 "$2/scenes/two_rooms.json"
h5diff clean.h5 keep.h5 || fail "keep.h5 changed"
# Outputs naming inputs or non-regular files, against a copy of the scene (never the sources').
cp -r "$2/scenes/shoebox.json" "$2/scenes/shoebox.obj" "$2/scenes/signals" .
expect_refusal "--out: 'shoebox.json' is the scene file" shoebox.json --out shoebox.json --spacing 2
expect_refusal "--out: 'shoebox.obj' is the mesh" shoebox.json --out shoebox.obj --spacing 2
mkfifo out.fifo
expect_refusal "--out: 'out.fifo' exists and is not a regular file" shoebox.json --out out.fifo \
  --spacing 2
[[ -p out.fifo ]] || fail "out.fifo was replaced"
ln -s loop2.h5 loop1.h5
ln -s loop1.h5 loop2.h5
expect_refusal "too many levels of symbolic links" shoebox.json --out loop1.h5 --spacing 2
[[ -L loop1.h5 && -L loop2.h5 ]] || fail "a link of the loop was replaced"
expect_refusal "--map: 'new.h5' is the bake" shoebox.json --out new.h5 --map new.h5 --spacing 2
expect_refusal "--map: 'shoebox.json' is the scene file" --resume keep.h5 shoebox.json \
  --map shoebox.json
mkdir dir.h5
expect_refusal "bake 'dir.h5' is a directory" --resume dir.h5
# A grid height beyond the coordinate limit: refused before any ray (it aborted inside Embree).
expect_refusal "--spacing/--height: probe coordinate y: 1e+20 is outside" shoebox.json \
  --out new.h5 --spacing 2 --height 1e20
h5diff clean.h5 keep.h5 || fail "keep.h5 changed"
# A dangling symbolic link as --out stays a link; the bake is written where it leads.
ln -s made.h5 link.h5
"$bake" shoebox.json --out link.h5 "${quick[@]}" --quiet
[[ -L link.h5 ]] && complete made.h5 || fail "the link was replaced or made.h5 not written"

if ! command -v mpirun >/dev/null || ! ldd "$bake" | grep -q libmpi; then
  echo "mpirun or an MPI build missing: MPI cases skipped"
  exit 0
fi
mpi=(mpirun -q --allow-run-as-root --oversubscribe)
echo "== mpirun -np 1 and -np 2 equal the single-process bake"
"$bake" "$scene" --out single.h5 "${quick[@]}" --quiet
"${mpi[@]}" -np 1 "$bake" "$scene" --out np1.h5 "${quick[@]}" --quiet
"${mpi[@]}" -np 2 "$bake" "$scene" --out np2.h5 "${quick[@]}" --quiet
h5diff single.h5 np1.h5 || fail "-np 1 differs"
h5diff single.h5 np2.h5 || fail "-np 2 differs"

echo "== an interrupted bake resumed under mpirun -np 2 equals the clean one"
"$bake" "$scene" --out cut2.h5 "${slow[@]}" 2>cut2.err & pid=$!
kill_after_first_probe cut2.err $pid TERM
if wait $pid; then fail "interrupted bake exited 0"; fi
"${mpi[@]}" -np 2 "$bake" --resume cut2.h5 --quiet --threads 1
h5diff clean.h5 cut2.h5 || fail "bake resumed under MPI differs from the clean one"

echo "== a rank killed mid-bake: dpc-bake's own line, non-zero exit, a file --resume completes"
# Rank 1 is killed once rank 0 has committed a probe; the job has 70 probes of about 0.1 s
# each, so it is still running. Rank 0 reports it (apps/bake/watchdog.h) whether it notices
# the rank's end or mpirun's signal first.
"${mpi[@]}" -np 2 "$bake" "$scene" --out killed.h5 "${slow[@]}" 2>killed.err & mp=$!
for _ in $(seq 1 600); do grep -q 'probes/s' killed.err 2>/dev/null && break; sleep 0.1; done
for p in $(pgrep -P $mp); do
  if tr '\0' '\n' </proc/"$p"/environ | grep -q '^OMPI_COMM_WORLD_RANK=1$'; then kill -KILL "$p"; fi
done
if wait $mp; then fail "job with a killed rank exited 0"; fi
line='killed.h5: rank 1 of 2 stopped; [0-9]+ of 70 probes committed, .* dpc-bake --resume killed.h5 finishes it'
[[ $(grep -cE "$line" killed.err) == 1 ]] || fail "no one-line report of the killed rank: $(cat killed.err)"
grep -q 'Read -1' killed.err && fail "rank 0 died in Open MPI's transport: $(cat killed.err)"
complete killed.h5 && fail "killed bake marked complete"
"$bake" --resume killed.h5 --quiet
h5diff clean.h5 killed.h5 || fail "resumed bake of the killed job differs from the clean one"
echo "all dpc-bake end-to-end cases pass"
