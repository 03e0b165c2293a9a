#!/usr/bin/env bash
# First-run command: installs what is missing, builds, and renders the default scene offline.
# Usage: scripts/render-demo.sh [SCENE.json] [extra dpc-demo flags...]
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh dpc-demo dpc-analyze
scene=${1:-scenes/hall.json}
shift || true
mkdir -p out
name=$(basename "$scene" .json)
./build/apps/dpc-demo "$scene" --offline "out/$name.wav" --ir-out "out/$name-ir.wav" "$@"
echo
echo "Listen to: $(pwd)/out/$name.wav"
echo "Room parameters of the last frame's IR: ./build/apps/dpc-analyze out/$name-ir.wav"
