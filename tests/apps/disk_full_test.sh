#!/usr/bin/env bash
# A full disk during an offline render: dpc-demo renders into a 512 kB tmpfs mounted in a
# private mount namespace (unshare -rm: no root needed where user namespaces are allowed; the
# mount vanishes with the process). Two renders, each with an earlier output already there:
#   1. --offline of 2 s of stereo float32 (768 kB) does not fit: exit 1, one line naming the
#      output and "No space left on device", the earlier file intact, no temporary left;
#   2. --offline of 0.3 s fits but --ir-out (the hall's IR, several hundred kB more) does not:
#      exit 1, and neither output written (all or nothing).
# With dpc-bake built, a bake (1.4 MB) onto the same 512 kB tmpfs:
#   3. refused before any probe, one line naming the file and the free space, exit 1, nothing
#      left on the tmpfs (no file, no temporary, no lock file);
#   4. with --force, the creation itself fails: one line naming the file and "No space left on
#      device", exit 1 (never a signal), nothing left;
#   5. a write refused in the middle of a bake (ENOSPC from the third probe on, as a
#      copy-on-write file system or a quota would: SHIM, tests/bake/enospc_shim.c, preloaded;
#      a tmpfs cannot, the file being allocated whole when it is created): one line naming the
#      file, exit 1, the file not complete; --resume then finishes it to the same bytes as a
#      clean bake (cmp);
#   6. the bake fits but its --map does not: exit 1, one line naming the map and saying the
#      bake is complete and how to write the map again (--resume --map), which then works.
# Exits 77 (ctest: skipped) where a private tmpfs cannot be mounted.
# Usage: disk_full_test.sh BUILD_DIR SOURCE_DIR [SHIM]
set -euo pipefail
build=$1
src=$2
shim=${3:-}
if ! unshare -rm true 2>/dev/null; then
  echo "SKIP: no private mount namespace here (unshare -rm)"
  exit 77
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mnt="$work/small"
mkdir -p "$mnt"

# Runs "$@" (a dpc-demo render into $mnt) in the namespace, then lists $mnt and prints
# earlier.wav's text: everything is seen from inside, before the mount goes.
in_small_disk() {
  unshare -rm bash -c '
    mnt=$1; shift
    mount -t tmpfs -o size=512k tmpfs "$mnt" || exit 90
    echo "an earlier render" >"$mnt/earlier.wav"
    status=0
    "$@" >"$mnt/../log.txt" 2>&1 || status=$?
    echo "status $status"
    ls -A "$mnt"
    cat "$mnt/earlier.wav"' _ "$mnt" "$@"
}

fail() {
  echo "FAIL: $1"
  cat "$work/log.txt"
  exit 1
}

out=$(in_small_disk "$build/apps/dpc-demo" "$src/scenes/shoebox.json" --offline \
      "$mnt/earlier.wav" --duration 2 --output stereo --rays 256 --quiet)
echo "$out"
[[ $(sed -n 1p <<<"$out") == "status 1" ]] || fail "render 1: expected exit status 1"
[[ $(sed -n 2,99p <<<"$out") == $'earlier.wav\nan earlier render' ]] ||
    fail "render 1: the tmpfs should hold only the intact earlier file"
grep -q "earlier.wav: cannot write.*No space left on device" "$work/log.txt" ||
    fail "render 1: no line naming the output and the full disk"
[[ $(grep -c "^dpc-demo: " "$work/log.txt") -eq 1 ]] || fail "render 1: not one error line"

out=$(in_small_disk "$build/apps/dpc-demo" "$src/scenes/hall.json" --offline \
      "$mnt/render.wav" --ir-out "$mnt/ir.wav" --duration 0.3 --output stereo --rays 256 --quiet)
echo "$out"
[[ $(sed -n 1p <<<"$out") == "status 1" ]] || fail "render 2: expected exit status 1"
[[ $(sed -n 2,99p <<<"$out") == $'earlier.wav\nan earlier render' ]] ||
    fail "render 2: neither output may be written when one does not fit"
grep -q "ir.wav: cannot write" "$work/log.txt" || fail "render 2: no line naming ir.wav"
bake=$build/apps/dpc-bake
if [[ ! -x $bake ]]; then
  echo "PASS: a full disk leaves no partial or temporary file and no earlier file changed"
  echo "(dpc-bake not built: bake cases skipped)"
  exit 0
fi
q=(--spacing 2 --rays 200 --frames 4 --threads 1 --quiet)
complete() { h5dump -a /complete "$1" | grep '(0): 1' >/dev/null; }
# refused_here NAME LISTING PATTERN: the run in $out ended with status 1, left the tmpfs
# holding LISTING (then earlier.wav's text), and printed one line matching PATTERN.
refused_here() {
  [[ $(sed -n 1p <<<"$out") == "status 1" ]] || fail "$1: expected exit status 1"
  [[ $(sed -n 2,99p <<<"$out") == "$2"$'\nan earlier render' ]] ||
      fail "$1: the tmpfs should hold only $2"
  grep -q "$3" "$work/log.txt" || fail "$1: no line matching $3"
  [[ $(wc -l <"$work/log.txt") -eq 1 ]] || fail "$1: not one line"
}

out=$(in_small_disk "$bake" "$src/scenes/shoebox.json" --out "$mnt/bake.h5" "${q[@]}")
echo "$out"
refused_here "bake 3" earlier.wav "^dpc-bake: $mnt/bake.h5: cannot write: the bake needs .* free"

out=$(in_small_disk "$bake" "$src/scenes/shoebox.json" --out "$mnt/bake.h5" "${q[@]}" --force)
echo "$out"
refused_here "bake 4" earlier.wav "^dpc-bake: $mnt/bake.h5: cannot write: .*No space left on device"

# The map does not fit (the tmpfs filled first), the bake does (written outside it): the bake
# stays complete, the one line says so and how to write the map again, no map or temporary.
out=$(in_small_disk bash -c 'head -c 500000 /dev/zero >"$1/filler" 2>/dev/null; shift; "$@"' _ \
      "$mnt" "$bake" "$src/scenes/shoebox.json" --out "$work/mapped.h5" --map "$mnt/m.csv" "${q[@]}")
echo "$out"
refused_here "bake 6" $'earlier.wav\nfiller' \
  "^dpc-bake: $mnt/m.csv: cannot write.*; the bake $work/mapped.h5 is complete: dpc-bake --resume $work/mapped.h5 --map $mnt/m.csv writes the map again"
complete "$work/mapped.h5" || fail "bake 6: the bake itself should be complete"
"$bake" --resume "$work/mapped.h5" --map "$work/m.csv" --quiet >/dev/null 2>&1 ||
    fail "bake 6: --resume --map did not write the map"
[[ $(wc -l <"$work/m.csv") -gt 15 ]] || fail "bake 6: the map written by --resume is empty"

if [[ -z $shim ]]; then
  echo "PASS (a write refused mid-bake not checked: no shim in this build)"
  exit 0
fi
cd "$work"
"$bake" "$src/scenes/shoebox.json" --out clean.h5 "${q[@]}"
size=$(stat -c %s clean.h5)
row=$(( size / 15 ))  # 15 probes: about one probe's bytes
status=0
# Creating the file writes only HDF5's metadata (a few kB; the rest is reserved with
# posix_fallocate): the writes fail in the third probe.
DPC_ENOSPC_NAME=cut.h5 DPC_ENOSPC_AFTER=$(( 2 * row + 16384 )) LD_PRELOAD=$shim \
  "$bake" "$src/scenes/shoebox.json" --out cut.h5 "${q[@]}" >log.txt 2>&1 || status=$?
cat log.txt
[[ $status == 1 ]] || fail "bake 5: exit status $status, expected 1"
[[ $(wc -l <log.txt) -eq 1 ]] || fail "bake 5: not one line"
grep -q "^dpc-bake: cut.h5: .*cannot write: No space left on device" log.txt ||
    fail "bake 5: no line naming the bake and the full disk"
complete cut.h5 && fail "bake 5: a bake whose writes failed is marked complete"
"$bake" --resume cut.h5 --quiet >log.txt 2>&1 || fail "bake 5: --resume failed"
cmp clean.h5 cut.h5 || fail "bake 5: the resumed bake differs from a clean one"
ls "$work" | grep lock >/dev/null && fail "bake 5: a lock file was left"
echo "PASS: a full disk leaves no partial or temporary file and no earlier file changed; a bake"
echo "      that does not fit is refused, one whose write fails is never complete and resumes"
