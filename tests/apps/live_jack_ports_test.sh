#!/usr/bin/env bash
# Live Ambisonic output through JACK's own client: dpc-demo plays the shoebox as first-order
# AmbiX on a JACK server of its own (dummy backend, period 64) with --device jack:sink, where
# "sink" is a JACK client (python3-jack-client) with four input ports that measures what
# arrives. Asserts: dpc-demo exits 0; its output ports are named ACN0..ACN3 and are connected
# in order to sink's inputs; the omnidirectional channel ACN0 carries sound (RMS > 1e-4, i.e.
# above -80 dBFS: the shoebox's speech plays at about -30 dBFS) and every channel is finite;
# --stats reports the engine block equal to the server's period (64: one block per callback).
# Usage: live_jack_ports_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$1
src=$2
# shellcheck source=jack_private_server.sh
source "$(dirname "$0")/jack_private_server.sh"
jack_private_setup dpc-ports "$src"
jack_private_start 64 "$work/jackd.log"

# The sink: four inputs; until told to stop (a file), it sums each port's squared samples and
# notes which ports feed it; then writes one JSON object.
cat >"$work/sink.py" <<'PY'
import json, math, os, sys, time
import jack
client = jack.Client("sink", no_start_server=True)
ports = [client.inports.register(f"in_{i + 1}") for i in range(4)]
energy = [0.0] * 4
count = [0]
finite = [True]
@client.set_process_callback
def process(frames):
    for i, p in enumerate(ports):
        a = p.get_array()
        s = float((a.astype("float64") ** 2).sum())
        if not math.isfinite(s):
            finite[0] = False
        else:
            energy[i] += s
    count[0] += frames
with client:
    feeders = {}
    while not os.path.exists(sys.argv[1] + ".stop"):
        for p in ports:
            names = [q.name for q in client.get_all_connections(p)]
            if names:
                feeders[p.name] = names
        time.sleep(0.1)
    rms = [math.sqrt(e / max(count[0], 1)) for e in energy]
    json.dump({"rms": rms, "frames": count[0], "finite": finite[0], "feeders": feeders},
              open(sys.argv[1], "w"))
PY
/usr/bin/python3 "$work/sink.py" "$work/sink.json" &
sink_pid=$!
pids+=($sink_pid)
for _ in $(seq 1 50); do
  jack_lsp 2>/dev/null | grep '^sink:in_4$' >/dev/null && break
  sleep 0.1
done

status=0
"$build/apps/dpc-demo" "$src/scenes/shoebox.json" --output ambisonics --ambisonic-order 1 \
    --device jack:sink --duration 4 --rays 512 --threads 1 --stats "$work/stats.json" \
    >"$work/demo.log" 2>&1 || status=$?
touch "$work/sink.json.stop"
wait "$sink_pid" || true
tr '\r' '\n' <"$work/demo.log" | grep -E '^(dpc-demo|playing|note|wrote|live)' || true
[[ $status -eq 0 ]] || { echo "FAIL: dpc-demo exit status $status"; exit 1; }

/usr/bin/python3 - "$work/sink.json" "$work/stats.json" <<'PY'
import json, sys
sink = json.load(open(sys.argv[1]))
stats = json.load(open(sys.argv[2]))
print("sink:", sink)
print("stats: block_frames", stats["block_frames"], "engine_block_frames",
      stats["engine_block_frames"], "channels", stats["channels"])
fail = []
for i in range(4):
    want = [f"dpc-demo:ACN{i}"]
    got = sink["feeders"].get(f"sink:in_{i + 1}")
    if got != want:
        fail.append(f"sink:in_{i + 1} fed by {got}, expected {want}")
if not sink["finite"]:
    fail.append("non-finite samples arrived")
if not sink["rms"][0] > 1e-4:
    fail.append(f"ACN0 silent (rms {sink['rms'][0]:.2e})")
if stats["channels"] != 4:
    fail.append(f"{stats['channels']} channels, expected 4")
if not (stats["block_frames"] == 64 and stats["engine_block_frames"] == 64):
    fail.append("the engine block is not the server's period (64)")
for f in fail:
    print("FAIL:", f)
sys.exit(1 if fail else 0)
PY
echo "PASS: AmbiX ports ACN0..ACN3 fed sink's inputs in order, engine block = period"
