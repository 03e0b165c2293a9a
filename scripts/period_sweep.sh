#!/usr/bin/env bash
# The live callback load against the JACK period: every shipped scene played by dpc-demo on a
# JACK dummy server at periods 64, 128, 256, 512 and 1024 frames (jackd -R where SCHED_FIFO is
# granted), the engine block taking the period, one --stats file per run in out/periods/.
# Then: /usr/bin/python3 scripts/plot_periods.py (docs/live.md, "Callback load per period").
# Usage: scripts/period_sweep.sh [SECONDS] [SCENES...]   (default 15 s, every scenes/*.json)
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-15}
shift || true
scenes=("$@")
((${#scenes[@]})) || scenes=(scenes/*.json)
mkdir -p out/periods
for scene in "${scenes[@]}"; do
  name=$(basename "$scene" .json)
  for period in 64 128 256 512 1024; do
    out=out/periods/$name-p$period.json
    echo "== $name, period $period" >&2
    JACK_PERIOD=$period scripts/jack-headless.sh ./build/apps/dpc-demo "$scene" \
        --duration "$seconds" --stats "$out" --quiet >/dev/null 2>out/periods/$name-p$period.log \
      || echo "   failed (see out/periods/$name-p$period.log)" >&2
  done
done
