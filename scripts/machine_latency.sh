#!/usr/bin/env bash
# The machine's own scheduling latency, the floor under any audio callback's worst case:
# cyclictest (Debian's rt-tests) wakes a SCHED_FIFO 99 thread every millisecond on CPU 0 for
# SECONDS and counts the wake-ups later than half and than all of a 64-frame period at 48 kHz
# (667 and 1333 us). On a machine that preempts even that thread (a VM's host, SMIs), no
# callback can be promised under 50 % of a short period, whatever it computes.
# Usage: scripts/machine_latency.sh [SECONDS]   (default 120; needs root for SCHED_FIFO 99)
set -euo pipefail
seconds=${1:-120}
if ! command -v cyclictest >/dev/null 2>&1; then
  sudo=""
  [[ $(id -u) -eq 0 ]] || sudo="sudo"
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y rt-tests >/dev/null
fi
hist=$(mktemp)
trap 'rm -f "$hist"' EXIT
cyclictest -m -p 99 -i 1000 -t 1 -a 0 -D "$seconds" -q -h 20000 --histfile="$hist" >/dev/null
/usr/bin/python3 - "$hist" <<'PY'
import sys
total = half = whole = 0
worst = None
for line in open(sys.argv[1]):
    if line.startswith("# Max Latencies:"):
        worst = int(line.split(":")[1])
    if line.startswith("#") or not line.strip():
        continue
    us, count = (int(x) for x in line.split()[:2])
    total += count
    half += count if us > 667 else 0
    whole += count if us > 1333 else 0
print(f'{{"wakeups": {total}, "over_667_us": {half}, "over_1333_us": {whole}, "max_us": {worst}}}')
PY
