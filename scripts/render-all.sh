#!/usr/bin/env bash
# Renders every shipped scene offline with a build's dpc-demo, in mono, stereo and binaural,
# with the last frame's impulse response (--ir-out) and energy response (--er-out), and writes
# the SHA-256 of every file to OUT_DIR/SHA256SUMS. scripts/check-identical.sh compares two
# builds' manifests: a change that must not alter behaviour leaves every file byte-identical.
# Usage: scripts/render-all.sh BUILD_DIR OUT_DIR [DURATION_S (default 1)]
set -euo pipefail
if (($# < 2)); then
  echo "usage: $0 BUILD_DIR OUT_DIR [DURATION_S]" >&2
  exit 2
fi
root=$(cd "$(dirname "$0")/.." && pwd)
build=$(cd "$1" && pwd)
mkdir -p "$2"
out=$(cd "$2" && pwd)
duration=${3:-1}
demo=$build/apps/dpc-demo
[[ -x $demo ]] || { echo "render-all: $demo is not built" >&2; exit 1; }
cd "$root"
for scene in scenes/*.json; do
  name=$(basename "$scene" .json)
  for output in mono stereo binaural; do
    stem=$out/$name-$output
    # Analysis CSVs of the IR give a second, independent view of any difference.
    "$demo" "$scene" --offline "$stem.wav" --duration "$duration" --output "$output" \
      --ir-out "$stem-ir.wav" --er-out "$stem-er.csv" --seed 7 --quiet --threads 2 \
      >"$stem.log" 2>&1 || { echo "render-all: $scene $output failed:" >&2; cat "$stem.log" >&2; exit 1; }
    rm -f "$stem.log"
  done
  echo "render-all: $name" >&2
done
# The stochastic estimator's other path: plain path tracing on one scene.
"$demo" scenes/shoebox.json --offline "$out/shoebox-pt.wav" --duration "$duration" \
  --estimator path_tracing --ir-out "$out/shoebox-pt-ir.wav" --quiet --seed 3 >/dev/null 2>&1
(cd "$out" && find . -type f ! -name SHA256SUMS | LC_ALL=C sort | xargs sha256sum >SHA256SUMS)
echo "render-all: $(wc -l <"$out/SHA256SUMS") files in $out/SHA256SUMS" >&2
