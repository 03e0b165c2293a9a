#!/usr/bin/env bash
# The issue's bake faults, tried as a user would (docs/hardening.md, "Bakes"): one line per
# fault saying whether the build accepted it silently or refused / recovered. Not a test (it
# asserts nothing; tests/bake/bake_cli_test.sh and the others do): it measures a build, e.g.
# main against a branch, for the before-and-after table. Needs mount (root or a user
# namespace), h5dump/h5diff and, for the MPI line, mpirun.
# Usage: scripts/bake_fault_survey.sh BUILD_DIR SOURCE_DIR
set -uo pipefail
B=$1; S=$2
bake=$B/apps/dpc-bake; demo=$B/apps/dpc-demo
W=$(mktemp -d); cd "$W"
q=(--spacing 2 --rays 200 --frames 4 --threads 1 --quiet)
cp "$S"/scenes/shoebox.json "$S"/scenes/shoebox.obj .; cp -r "$S"/scenes/signals .
complete() { h5dump -a /complete "$1" 2>/dev/null | grep '(0): 1' >/dev/null; }
res() { echo "$1: $2"; }
"$bake" shoebox.json --out clean.h5 "${q[@]}" 2>/dev/null
# 1 disk full
mkdir -p mnt
unshare -rm bash -c "mount -t tmpfs -o size=512k tmpfs mnt && { '$bake' shoebox.json --out mnt/full.h5 ${q[*]} >full.log 2>&1; echo \$? > full.status; cp mnt/full.h5 full.h5 2>/dev/null; true; }"
st=$(cat full.status); lines=$(wc -l < full.log)
if complete full.h5; then res "disk full (512k tmpfs)" "ACCEPTED: marked complete, status $st, $(head -c 200 full.log|tr '\n' '|')"; else res "disk full" "refused: status $st, $lines lines: $(head -c 200 full.log|tr '\n' '|')"; fi
# 2 SIGKILL mid-write, then resume equals clean
"$bake" shoebox.json --out killed.h5 --spacing 1 --rays 200 --frames 4 --threads 1 2>k.err & p=$!
for i in $(seq 1 300); do grep -q 'probes/s' k.err 2>/dev/null && break; sleep 0.05; done; kill -KILL $p; wait $p 2>/dev/null
complete killed.h5 && res "SIGKILL" "ACCEPTED: complete" || res "SIGKILL" "not complete"
"$bake" shoebox.json --out clean1.h5 --spacing 1 --rays 200 --frames 4 --threads 1 --quiet 2>/dev/null
"$bake" --resume killed.h5 --quiet >/dev/null 2>&1; h5diff -q clean1.h5 killed.h5 >/dev/null 2>&1 && res "SIGKILL+resume" "recovered (h5diff equal)" || res "SIGKILL+resume" "DIFFERS or failed"
# 3 two writers
"$bake" shoebox.json --out two.h5 --spacing 1 --rays 200 --frames 4 --threads 1 --quiet 2>w1.err & p1=$!
sleep 0.3
"$bake" shoebox.json --out two.h5 --spacing 1 --rays 200 --frames 4 --threads 1 --quiet 2>w2.err & p2=$!
s1=0; wait $p1 || s1=$?; s2=0; wait $p2 || s2=$?
if [[ $s1 == 0 && $s2 == 0 ]]; then res "two writers" "ACCEPTED: both exit 0"; else res "two writers" "refused ($s1/$s2): $(cat w1.err w2.err|head -c 200)"; fi
# 4 resume with each changed setting
mk() { python3 - "$@" <<'PY'
import json,sys
name, path, val = sys.argv[1], sys.argv[2], sys.argv[3]
s = json.load(open('shoebox.json'))
cur = s
keys = path.split('.')
for k in keys[:-1]:
    cur = cur[int(k)] if k.isdigit() else cur.setdefault(k, {})
cur[keys[-1]] = json.loads(val)
json.dump(s, open(name, 'w'))
PY
}
declare -A changes=(
 [seed]='propagation.seed 7' [radius]='listener.radius 0.4' [absorption]='materials.floor {"absorption":[0.3,0.3,0.3,0.3,0.3,0.3,0.3,0.3]}'
 [scattering]='materials.walls {"library":"plasterboard_on_frame","scattering":0.5}'
 [transmission]='materials.walls {"library":"plasterboard_on_frame","scattering":0.2,"transmission_loss_db":30}'
 [source_pos]='sources.0.position [2.5,1.6,3.5]' [directivity]='sources.0.directivity "cardioid"'
 [exact_order]='propagation.exact_order 2' [max_order]='propagation.max_order 100' [ir_length]='propagation.ir_length 1.0'
 [temperature]='propagation.temperature 25' )
for k in "${!changes[@]}"; do
  set -- ${changes[$k]}; path=$1; shift; val="$*"
  mk "s_$k.json" "$path" "$val"
  "$bake" shoebox.json --out "r_$k.h5" --spacing 1 --rays 200 --frames 4 --threads 1 2>r.err & p=$!
  for i in $(seq 1 300); do grep -q 'probes/s' r.err 2>/dev/null && break; sleep 0.05; done; kill -TERM $p; wait $p 2>/dev/null
  if "$bake" --resume "r_$k.h5" "s_$k.json" --quiet >/dev/null 2>rr.err && complete "r_$k.h5"; then res "resume changed $k" "ACCEPTED (complete)"; else res "resume changed $k" "refused: $(head -c 150 rr.err)"; fi
done
# 5 playback on another scene / other IR length
mk s_ir1.json propagation.ir_length 1.0
"$demo" s_ir1.json --offline o.wav --duration 0.3 --bake clean.h5 --quiet >/dev/null 2>p.err && res "play 2s bake on 1s scene" "ACCEPTED" || res "play 2s bake on 1s scene" "refused: $(head -c 150 p.err)"
mk s_seed.json propagation.seed 9
"$demo" s_seed.json --offline o.wav --duration 0.3 --bake clean.h5 --quiet >/dev/null 2>p.err && res "play on scene with other seed" "accepted" || res "play on other seed" "refused: $(head -c 150 p.err)"
mk s_tl.json materials.walls '{"library":"plasterboard_on_frame","scattering":0.2,"transmission_loss_db":30}'
"$demo" s_tl.json --offline o.wav --duration 0.3 --bake clean.h5 --quiet >/dev/null 2>p.err && res "play on scene with transmission loss" "ACCEPTED" || res "play TL" "refused: $(head -c 150 p.err)"
mk s_eo.json propagation.exact_order 0
"$demo" s_eo.json --offline o.wav --duration 0.3 --bake clean.h5 --quiet >/dev/null 2>p.err && res "play on scene with exact_order 0" "ACCEPTED" || res "play exact_order" "refused: $(head -c 150 p.err)"
"$demo" "$S/scenes/two_rooms.json" --offline o.wav --duration 0.3 --bake clean.h5 --quiet >/dev/null 2>p.err && res "play on two_rooms" "ACCEPTED" || res "play on two_rooms" "refused"
# 6 flipped bytes and truncations
acc=0; n=0
for seed in 1 2 3 4 5; do
  cp clean.h5 f.h5
  python3 -c "
import random,sys
r=random.Random($seed); b=bytearray(open('f.h5','rb').read())
for _ in range(300):
  i=r.randrange(len(b)); b[i]^=1<<r.randrange(8)
open('f.h5','wb').write(b)"
  n=$((n+1)); "$demo" shoebox.json --offline o.wav --duration 0.3 --bake f.h5 --quiet >/dev/null 2>/dev/null && acc=$((acc+1))
done
res "300 flipped bytes (5 seeds), played" "$acc of $n ACCEPTED"
acc=0; n=0; size=$(stat -c %s clean.h5)
for frac in 10 50 90 99 999; do
  head -c $((size * frac / (frac < 100 ? 100 : 1000))) clean.h5 > t.h5
  n=$((n+1)); "$demo" shoebox.json --offline o.wav --duration 0.3 --bake t.h5 --quiet >/dev/null 2>/dev/null && acc=$((acc+1))
done
res "truncations (10,50,90,99,99.9 %)" "$acc of $n ACCEPTED"
# 7 spacing 0.01
timeout 20 "$bake" shoebox.json --out sp.h5 --spacing 0.01 >sp.log 2>&1; st=$?
[[ $st == 124 ]] && res "--spacing 0.01" "ACCEPTED (still running after 20 s): $(head -c 200 sp.log|tr '\n' '|')" || res "--spacing 0.01" "status $st: $(head -c 200 sp.log)"
# 8 MPI file identity
if command -v mpirun >/dev/null; then
  for np in 1 2 3; do mpirun -q --allow-run-as-root --oversubscribe -np $np "$bake" shoebox.json --out np$np.h5 "${q[@]}" 2>/dev/null; done
  same=0; for np in 1 2 3; do cmp -s clean.h5 np$np.h5 && same=$((same+1)); done
  h5same=0; for np in 1 2 3; do h5diff -q clean.h5 np$np.h5 >/dev/null && h5same=$((h5same+1)); done
  res "mpirun -np 1/2/3 vs single" "$same of 3 byte-identical, $h5same of 3 h5diff-equal"
fi
"$bake" shoebox.json --out again.h5 "${q[@]}" 2>/dev/null; cmp -s clean.h5 again.h5 && res "two clean runs" "byte-identical" || res "two clean runs" "NOT byte-identical"
cd /; rm -rf "$W"
