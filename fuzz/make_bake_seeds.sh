#!/usr/bin/env bash
# Makes the bake fuzzer's seed corpus (fuzz/corpus/bake): small valid bakes, each under the
# 64 kB fuzz.sh gives an input (0.1 s responses, 1 or 2 probes, few rays), of the shoebox (one
# source; also with its wave band at 16 kHz) and of two_rooms (two sources), and damaged
# copies (truncated, a flipped data byte, a flipped metadata byte) that the reader must refuse.
# The valid bakes are named valid-*: ctest fuzz_replay:bake fails when the fuzzer refuses one
# (fuzz/fuzz_report.h). valid-format5-shoebox-2-probes.h5 is kept from an older dpc-bake: the
# oldest format the reader still reads (docs/bake-format.md), which this script cannot write.
# Usage: fuzz/make_bake_seeds.sh BUILD_DIR   (needs BUILD_DIR/apps/dpc-bake)
set -euo pipefail
cd "$(dirname "$0")/.."
bake=$1/apps/dpc-bake
out=fuzz/corpus/bake
# A fixed folder: the bakes record their scene's path, so the seeds come out the same bytes.
work=/tmp/dpc_bake_seeds
rm -rf "$work" && mkdir -p "$work"
trap 'rm -rf "$work"' EXIT
mkdir -p "$out"
short() {  # short SCENE NAME [KEY JSON]: the scene with 0.1 s responses, its files named
  # absolutely, and the top-level KEY set to JSON
  /usr/bin/python3 - "$PWD/scenes/$1" "$work/$2.json" "${@:3}" <<'PY'
import json, os, sys
src, dst = sys.argv[1], sys.argv[2]
s = json.load(open(src))
folder = os.path.dirname(src)
s["mesh"] = os.path.join(folder, s["mesh"])
for source in s["sources"]:
    if "signal" in source:
        source["signal"] = os.path.join(folder, source["signal"])
for obj in s.get("objects", []):
    obj["mesh"] = os.path.join(folder, obj["mesh"])
s.setdefault("propagation", {})["ir_length"] = 0.1
if len(sys.argv) > 4:
    s[sys.argv[3]] = json.loads(sys.argv[4])
json.dump(s, open(dst, "w"))
PY
}
short shoebox.json shoebox
short two_rooms.json two_rooms
printf '5 1.6 3.5\n3 1.6 2\n' >"$work/shoebox.txt"
"$bake" "$work/shoebox.json" --out "$out/valid-shoebox-2-probes.h5" --probes "$work/shoebox.txt" \
  --rays 64 --frames 4 --threads 1 --quiet
"$bake" "$work/shoebox.json" --out "$work/cut.h5" --probes "$work/shoebox.txt" --rays 64 \
  --frames 4 --threads 1 --quiet
/usr/bin/python3 - "$work/cut.h5" "$out" <<'PY'
import sys
import h5py
with h5py.File(sys.argv[1], "r") as f:
    energy = f["energy"].id.get_offset()  # contiguous: the first probe's row starts here
b = open(sys.argv[1], "rb").read()
out = sys.argv[2]
open(out + "/shoebox-truncated.h5", "wb").write(b[: len(b) * 2 // 3])
data = bytearray(b); data[energy + 1000] ^= 0x08
open(out + "/shoebox-data-flip.h5", "wb").write(data)
meta = bytearray(b); meta[300] ^= 0x01
open(out + "/shoebox-metadata-flip.h5", "wb").write(meta)
PY
printf '2 1.5 2\n' >"$work/two_rooms.txt"
"$bake" "$work/two_rooms.json" --out "$out/valid-two_rooms-1-probe.h5" \
  --probes "$work/two_rooms.txt" --rays 64 --frames 4 --threads 1 --quiet
# The wave band: 16 kHz and up to 200 Hz, so that one probe's band (1,600 floats) stays small.
short shoebox.json shoebox_wave wave '{"enabled": true, "max_frequency": 200}'
/usr/bin/python3 - "$work/shoebox_wave.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
s.setdefault("audio", {})["sample_rate"] = 16000
json.dump(s, open(sys.argv[1], "w"))
PY
printf '5 1.6 3.5\n' >"$work/shoebox_wave.txt"
"$bake" "$work/shoebox_wave.json" --out "$out/valid-shoebox-wave-1-probe.h5" \
  --probes "$work/shoebox_wave.txt" --rays 64 --frames 4 --threads 1 --quiet
ls -l "$out"
