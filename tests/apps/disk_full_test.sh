#!/usr/bin/env bash
# A full disk during an offline render: dpc-demo renders into a 512 kB tmpfs mounted in a
# private mount namespace (unshare -rm: no root needed where user namespaces are allowed; the
# mount vanishes with the process). Two renders, each with an earlier output already there:
#   1. --offline of 2 s of stereo float32 (768 kB) does not fit: exit 1, one line naming the
#      output and "No space left on device", the earlier file intact, no temporary left;
#   2. --offline of 0.3 s fits but --ir-out (the hall's IR, several hundred kB more) does not:
#      exit 1, and neither output written (all or nothing).
# Exits 77 (ctest: skipped) where a private tmpfs cannot be mounted.
# Usage: disk_full_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$1
src=$2
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
echo "PASS: a full disk leaves no partial or temporary file and no earlier file changed"
