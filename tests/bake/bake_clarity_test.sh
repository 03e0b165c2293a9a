#!/usr/bin/env bash
# A user's bake and map, C50 and C80 checked by an independent oracle (check_clarity.py: NumPy
# on each probe's stored energy response). Usage: bake_clarity_test.sh BUILD_DIR SOURCE_DIR PYTHON
set -euo pipefail
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$1/apps/dpc-bake" "$2/scenes/shoebox.json" --out "$work/b.h5" --map "$work/map.csv" \
  --spacing 2 --rays 500 --frames 4 --threads 1 --quiet
"$3" "$2/tests/bake/check_clarity.py" "$work/b.h5" "$work/map.csv"
