#!/usr/bin/env bash
# dpc-bake end to end: a bake interrupted (SIGTERM, SIGHUP, SIGINT: exit 128 + n, or SIGKILL)
# and resumed is the same file, byte for byte (cmp), as a clean one; a second dpc-bake on the
# same file is refused while the first runs; --resume refuses a scene changed in any setting
# that changes a probe, naming it, and settings that do not change a probe leave the file
# byte-identical; a grid over the limits is refused at once with its estimate; dpc-demo refuses
# a bake of another response length or scene and a damaged one; with Open MPI (when mpirun is
# installed), -np 1, 2 and 3 write the same bytes as the single-process run, and a rank killed
# mid-bake ends the job non-zero with a file --resume completes to the same bytes; bad input
# gets one line naming file and field, exit 1, no file created or changed.
# Files compared with cmp, datasets with h5diff (Debian hdf5-tools).
# Usage: bake_cli_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
bake="$1/apps/dpc-bake"
demo="$1/apps/dpc-demo"
scene="$2/scenes/shoebox.json"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
fail() { echo "FAIL: $*" >&2; exit 1; }
quick=(--spacing 2 --rays 500 --frames 4 --threads 1)
slow=(--spacing 1 --rays 1000 --frames 4 --threads 1)
complete() { h5dump -a /complete "$1" | grep '(0): 1' >/dev/null; }

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
cp cut.h5 cut-kept.h5
"$bake" --resume cut.h5 --quiet
cmp clean.h5 cut.h5 || fail "resumed bake differs from the clean one"

echo "== Ctrl-C pressed again while a probe runs ends the bake at once, still resumable"
# One probe of 100,000 rays x 8 frames takes seconds; the first SIGINT is taken after it, the
# second 0.6 s later ends the process by the signal (a person asking again); the same request
# delivered twice at once would be one (tests/wave/wave_test.py stop).
echo "5 1.5 3.5" >one-probe.txt
"$bake" "$scene" --out again.h5 --probes one-probe.txt --rays 100000 --frames 8 \
  2>again.err & pid=$!
for _ in $(seq 1 600); do  # the plan's line: the probe starts next
  grep -q 'probes to bake' again.err 2>/dev/null && break
  sleep 0.1
done
sleep 0.5
kill -INT $pid
sleep 0.6
kill -INT $pid 2>/dev/null || true
status=0; wait $pid || status=$?
[[ $status == $((128 + $(kill -l INT))) ]] && grep -q "interrupted by SIGINT" again.err &&
  fail "a second Ctrl-C 0.6 s later waited for the probe: $(cat again.err)"
[[ $status != 0 ]] || fail "a bake asked twice to stop exited 0"
complete again.h5 2>/dev/null && fail "a bake stopped twice marked complete"

echo "== SIGKILL mid-write, twice: never complete; --resume gives the clean bake's bytes"
"$bake" "$scene" --out killed1.h5 "${slow[@]}" 2>k1.err & pid=$!
kill_after_first_probe k1.err $pid KILL
if wait $pid; then fail "killed bake exited 0"; fi
complete killed1.h5 && fail "bake killed with SIGKILL marked complete"
"$bake" --resume killed1.h5 2>k2.err & pid=$!
kill_after_first_probe k2.err $pid KILL
if wait $pid; then fail "killed resume exited 0"; fi
complete killed1.h5 && fail "resume killed with SIGKILL marked complete"
"$bake" --resume killed1.h5 --quiet
cmp clean.h5 killed1.h5 || fail "bake resumed after SIGKILLs differs from the clean one"

echo "== a new bake over a complete one leaves it whole until the new one is complete"
# It was replaced when the new bake started: interrupted, a complete bake was lost.
cp clean.h5 over.h5
"$bake" "$scene" --out over.h5 "${slow[@]}" 2>over.err & pid=$!
kill_after_first_probe over.err $pid INT
status=0; wait $pid || status=$?
[[ $status == 130 ]] || fail "bake over a complete one: exit status $status"
cmp clean.h5 over.h5 || fail "an interrupted bake changed the complete bake at --out"
grep -q "over.h5.partial: interrupted by SIGINT .* --resume over.h5.partial finishes it and then \
replaces over.h5" over.err || fail "no line naming the partial bake: $(cat over.err)"
# The map may not name the bake the partial will replace (it overwrote it once complete).
status=0; "$bake" --resume over.h5.partial --map over.h5 --quiet 2>map.err || status=$?
[[ $status == 1 ]] && grep -q "'over.h5' is the bake" map.err || fail "--map over.h5: $(cat map.err)"
cmp clean.h5 over.h5 || fail "a refused --map changed the complete bake"
"$bake" --resume over.h5.partial --quiet
[[ ! -e over.h5.partial ]] || fail "over.h5.partial left beside the completed bake"
cmp clean.h5 over.h5 || fail "the resumed partial bake differs from the clean one"

echo "== one writer per file: a second dpc-bake on the same file is refused while one runs"
"$bake" "$scene" --out shared.h5 "${slow[@]}" 2>w1.err & pid=$!
kill_after_first_probe w1.err $pid 0  # signal 0: only waits for the first probe
ln -s shared.h5 alias.h5
for second in shared.h5 alias.h5; do
  status=0
  "$bake" "$scene" --out $second "${quick[@]}" 2>w2.err || status=$?
  [[ $status == 1 && $(wc -l <w2.err) == 1 ]] || fail "second writer of $second: $(cat w2.err)"
  grep -q "^dpc-bake: $second: another dpc-bake (pid $pid) is writing this bake" w2.err ||
    fail "second writer of $second: $(cat w2.err)"
done
status=0
"$bake" --resume shared.h5 2>w2.err || status=$?
[[ $status == 1 ]] && grep -q "another dpc-bake (pid $pid)" w2.err ||
  fail "resume of a bake in progress: $(cat w2.err)"
status=0
"$demo" "$scene" --offline o.wav --duration 0.2 --bake shared.h5 --quiet 2>w2.err || status=$?
[[ $status == 1 && $(wc -l <w2.err) == 1 ]] || fail "playing a bake in progress: $(cat w2.err)"
wait $pid || fail "the first writer failed"
cmp clean.h5 shared.h5 || fail "the first writer's bake differs from a clean one"
[[ -e shared.h5.lock ]] && fail "the lock file was left"

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
h5dump -a /probe_layout box.h5 | grep '"box 3 0.5 2 7 2.5 5"' >/dev/null || fail "probe_layout"
h5dump -a /grid_candidates box.h5 | grep '(0): 24' >/dev/null || fail "box candidates"

echo "== the energy max_order cuts off is reported, as dpc-demo reports it"
# max_order 3 in the shoebox (alpha about 0.1-0.3): after three reflections a ray still
# carries (1 - alpha)^3, over half of what it left with; the bake must say so, also --quiet.
sed 's/"max_order": 200/"max_order": 3/' "$scene" >order3.json
cp "$2/scenes/shoebox.obj" .
cp -r "$2/scenes/signals" .
grep -q '"max_order": 3' order3.json || fail "order3.json: max_order not set"
"$bake" order3.json --out order3.h5 "${quick[@]}" --quiet 2>order3.err
grep -qE '^dpc-bake: warning: order3.json: propagation.max_order: rays ended at order 3 still carried [0-9]+ % of the emitted energy' order3.err ||
  fail "no max_order warning: $(cat order3.err)"
"$bake" "$scene" --out order200.h5 "${quick[@]}" --quiet 2>order200.err
grep -q max_order order200.err && fail "max_order warned at the default order: $(cat order200.err)"
rm -f order3.h5 order200.h5 order3.err order200.err order3.json

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
# The partial bake's suffix is reserved: completed, X.partial replaces X.
expect_refusal "command line: --out: 'x.partial' ends in .partial" "$scene" --out x.partial \
  --spacing 2
# A --map folder that takes no file is refused before the bake (it replaced --out first).
expect_refusal "command line: --map: folder '/proc' is not writable" "$scene" --out keep.h5 \
  --spacing 2 --map /proc/m.csv
# An output named for another format than it writes (an HDF5 bake under b.wav, a CSV map under
# m.wav), and a read-only folder, which root may write into but the user marked (mode 555).
expect_refusal "command line: --out: 'b.wav' names a WAV file, but --out writes HDF5" "$scene" \
  --out b.wav --spacing 2
expect_refusal "command line: --map: 'm.wav' names a WAV file, but --map writes CSV" "$scene" \
  --out new.h5 --spacing 2 --map m.wav
mkdir -m 555 ro
expect_refusal "is not writable" "$scene" --out ro/b.h5 --spacing 2
[[ -z $(ls -A ro) ]] || fail "a file was made in the read-only folder"
expect_refusal "command line: --out: is empty" "$scene" --out "" --spacing 2
expect_refusal "command line: --spacing: is empty" "$scene" --out new.h5 --spacing ""
expect_refusal --spacing "$scene" --out keep.h5 --spacing 0
expect_refusal "--spacing: -1 m is not > 0" "$scene" --out keep.h5 --spacing -1
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
expect_refusal hash_geometry --resume other.h5 "$2/scenes/two_rooms.json"
# Over the limits: refused at once with the estimate, before any probe is placed.
expect_refusal "--spacing: up to 700000 probes, a file of up to .* GB, up to about" "$scene" \
  --out keep.h5 --spacing 0.01
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
# The --probes list is an input too (it was replaced by the bake or the map, exit status 0).
printf '5 1.6 3.5\n' >probes.txt
expect_refusal "--out: 'probes.txt' is the probe list" shoebox.json --probes probes.txt \
  --out probes.txt --rays 100 --frames 4 --threads 1 --quiet
expect_refusal "--map: 'probes.txt' is the probe list" shoebox.json --probes probes.txt \
  --out new.h5 --map probes.txt --rays 100 --frames 4 --threads 1 --quiet
[[ $(cat probes.txt) == "5 1.6 3.5" ]] || fail "probes.txt changed"
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

echo "== --resume refuses a changed setting, naming it; settings that do not change a probe"
# mkscene NAME JSON_PATH VALUE: shoebox.json (the copy here) with one key changed.
mkscene() {
  /usr/bin/python3 - "$@" <<'PY'
import json, sys
name, path, value = sys.argv[1], sys.argv[2].split("."), json.loads(sys.argv[3])
scene = json.load(open("shoebox.json"))
node = scene
for key in path[:-1]:
    node = node[int(key)] if key.isdigit() else node.setdefault(key, {})
node[path[-1]] = value
json.dump(scene, open(name, "w"))
PY
}
cp "$2/scenes/shoebox-corner.obj" .
while read -r field path value; do
  mkscene changed.json "$path" "$value"
  cp cut-kept.h5 try.h5
  expect_refusal "try.h5: $field" --resume try.h5 changed.json
  cmp cut-kept.h5 try.h5 || fail "a refused resume changed the file"
done <<'CHANGES'
seed propagation.seed 7
probe_radius_m listener.radius 0.4
ir_length_s propagation.ir_length 1.0
hash_materials materials.floor {"absorption":[0.3,0.3,0.3,0.3,0.3,0.3,0.3,0.3]}
hash_materials materials.walls {"library":"plasterboard_on_frame","scattering":0.5}
hash_materials materials.walls {"library":"plasterboard_on_frame","scattering":0.2,"transmission_loss_db":30}
hash_sources sources.0.position [2.5,1.6,3.5]
hash_sources sources.0.directivity "cardioid"
hash_physics propagation.exact_order 2
hash_physics propagation.max_order 100
hash_physics propagation.temperature 25
hash_physics propagation.air_absorption false
hash_physics propagation.diffraction false
hash_sampling propagation.patch_size 0.25
hash_geometry mesh "shoebox-corner.obj"
CHANGES
# What does not change a probe (the bake traces plain path tracing; audio is synthesised at
# playback): changed all at once, the bake is the same file.
cp shoebox.json shoebox-orig.json
/usr/bin/python3 - <<'PY'
import json
s = json.load(open("shoebox.json"))
s["propagation"].update({"cache_tau": 0.3, "estimator": "path_tracing",
                         "dpc_weighting": "seed", "frame_rate": 30, "rays_per_frame": 999})
s["audio"] = {"sample_rate": 44100, "block_size": 256, "output": "stereo"}
s["sources"][0]["gain_db"] = -6
json.dump(s, open("shoebox.json", "w"))
PY
"$bake" shoebox.json --out unchanged.h5 --rays 500 --frames 4 --spacing 2 --threads 1 --quiet
mv shoebox-orig.json shoebox.json
"$bake" shoebox.json --out reference.h5 --rays 500 --frames 4 --spacing 2 --threads 1 --quiet
cmp reference.h5 unchanged.h5 || fail "a setting outside the hash changed the bake"

echo "== dpc-demo refuses a bake of another response length, of another scene, or damaged"
mkscene short.json propagation.ir_length 1.0
expect_play_refusal() {  # expect_play_refusal WORD SCENE BAKE
  local status=0
  "$demo" "$2" --offline o.wav --duration 0.2 --bake "$3" --quiet 2>err.txt || status=$?
  [[ $status == 1 && $(wc -l <err.txt) == 1 ]] || fail "played $3 on $2: $(cat err.txt)"
  grep -q -- "$1" err.txt || fail "line does not name $1: $(cat err.txt)"
}
expect_play_refusal "reference.h5: ir_length_s: the bake's responses are 2 s long, short.json's ir_length is 1 s" short.json \
  reference.h5
expect_play_refusal "reference.h5: hash_geometry" "$2/scenes/two_rooms.json" reference.h5
cp reference.h5 flipped.h5
/usr/bin/python3 -c "
import random
r = random.Random(1); b = bytearray(open('flipped.h5', 'rb').read())
for _ in range(300):
    i = r.randrange(len(b)); b[i] ^= 1 << r.randrange(8)
open('flipped.h5', 'wb').write(b)"
expect_play_refusal "flipped.h5: " shoebox.json flipped.h5
"$demo" shoebox.json --offline o.wav --duration 0.2 --bake reference.h5 --quiet ||
  fail "the bake of this scene does not play"

if ! command -v mpirun >/dev/null || ! ldd "$bake" | grep libmpi >/dev/null; then
  echo "mpirun or an MPI build missing: MPI cases skipped"
  exit 0
fi
mpi=(mpirun -q --allow-run-as-root --oversubscribe)
echo "== mpirun -np 1, 2 and 3 write the single-process bake's bytes"
"$bake" "$scene" --out single.h5 "${quick[@]}" --quiet
for np in 1 2 3; do
  "${mpi[@]}" -np $np "$bake" "$scene" --out np$np.h5 "${quick[@]}" --quiet
  cmp single.h5 np$np.h5 || fail "-np $np differs"
done

echo "== an interrupted bake resumed under mpirun -np 2 equals the clean one"
"$bake" "$scene" --out cut2.h5 "${slow[@]}" 2>cut2.err & pid=$!
kill_after_first_probe cut2.err $pid TERM
if wait $pid; then fail "interrupted bake exited 0"; fi
"${mpi[@]}" -np 2 "$bake" --resume cut2.h5 --quiet --threads 1
cmp clean.h5 cut2.h5 || fail "bake resumed under MPI differs from the clean one"

echo "== a rank killed mid-bake: dpc-bake's own line, non-zero exit, a file --resume completes"
# Rank 1 is killed once rank 0 has committed a probe; the job has 70 probes of about 0.1 s
# each, so it is still running. Rank 0 reports it (apps/bake/watchdog.h) whether it notices
# the rank's end or mpirun's signal first.
"${mpi[@]}" -np 2 "$bake" "$scene" --out killed.h5 "${slow[@]}" 2>killed.err & mp=$!
for _ in $(seq 1 600); do grep -q 'probes/s' killed.err 2>/dev/null && break; sleep 0.1; done
for p in $(pgrep -P $mp); do
  if tr '\0' '\n' </proc/"$p"/environ | grep '^OMPI_COMM_WORLD_RANK=1$' >/dev/null; then kill -KILL "$p"; fi
done
if wait $mp; then fail "job with a killed rank exited 0"; fi
line='killed.h5: rank 1 of 2 stopped; [0-9]+ of 70 probes committed, .* dpc-bake --resume killed.h5 finishes it'
[[ $(grep -cE "$line" killed.err) == 1 ]] || fail "no one-line report of the killed rank: $(cat killed.err)"
grep -q 'Read -1' killed.err && fail "rank 0 died in Open MPI's transport: $(cat killed.err)"
complete killed.h5 && fail "killed bake marked complete"
"$bake" --resume killed.h5 --quiet
cmp clean.h5 killed.h5 || fail "resumed bake of the killed job differs from the clean one"
echo "all dpc-bake end-to-end cases pass"
