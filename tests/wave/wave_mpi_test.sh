#!/usr/bin/env bash
# dpc-wave as a user runs it on a cluster: the shoebox's low band alone, then under
# `mpirun -np 2` and `-np 4` (each rank steps one slab of the grid and trades its edge slices
# every step): the three WAV files must equal the single process's byte for byte. A scene error
# under mpirun is one line from rank 0, exit status 1, and no file.
# Usage: wave_mpi_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$1
src=$2
wave=$build/apps/dpc-wave
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
ldd "$wave" | grep libmpi >/dev/null || fail "dpc-wave is not built with MPI (mpirun is installed)"
mpi=(mpirun -q --allow-run-as-root --oversubscribe)
args=("$src/scenes/shoebox.json" --max-frequency 250 --seconds 0.4)
"$wave" "${args[@]}" --out "$work/alone.wav" >"$work/alone.log"
for np in 2 4; do
  "${mpi[@]}" -np $np "$wave" "${args[@]}" --out "$work/np$np.wav" >"$work/np$np.log"
  cmp "$work/alone.wav" "$work/np$np.wav" || fail "mpirun -np $np differs from one process"
  [[ $(grep -c '^wrote ' "$work/np$np.log") == 1 ]] || fail "-np $np: not one 'wrote' line"
  echo "mpirun -np $np: the single process's bytes"
done
# The IR holds sound (two equal empty files would pass the comparison).
/usr/bin/python3 - "$work/alone.wav" <<'PY'
import sys, numpy as np
from scipy.io import wavfile
rate, x = wavfile.read(sys.argv[1])
peak = float(np.max(np.abs(x)))
print(f"peak {peak:.4g} at {rate} Hz, {len(x)} samples")
sys.exit(0 if peak > 0 and np.all(np.isfinite(x)) else 1)
PY
set +e
"${mpi[@]}" -np 2 "$wave" "${args[@]}" --source 7 --out "$work/bad.wav" >"$work/bad.out" 2>"$work/bad.err"
status=$?
set -e
[[ $status != 0 ]] || fail "a bad --source under mpirun exited 0"
[[ ! -e $work/bad.wav ]] || fail "a bad --source under mpirun wrote a file"
grep -q -- '--source' "$work/bad.err" || fail "no line naming --source: $(cat "$work/bad.err")"
[[ $(grep -c 'dpc-wave' "$work/bad.err") == 1 ]] || fail "not one error line: $(cat "$work/bad.err")"
echo "PASS: dpc-wave under mpirun -np 2 and 4 equals one process, bad input refused once"
