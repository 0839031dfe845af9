#!/usr/bin/env bash
# Hardware-in-the-loop check of docs/realtime.md: a 100 Hz DMC loop for 60 s
# against `pneumid plant-server` on 127.0.0.1, compared with the offline
# simulation of the same scenario, then a 1 kHz loop for 10 s on the sim backend.
# Usage: bash bench/realtime_hil.sh [path/to/pneumid] [duration_s]
set -eu
PNEUMID=${1:-./pneumid}
DURATION=${2:-60}
OUT=${OUT:-$(mktemp -d)}
SETPOINT="staircase:levels=0 40 80 120 80 40,dwell=5,at=0.5"

"$PNEUMID" plant-server --plant ipa --port 0 > "$OUT/server.txt" &
SERVER=$!
trap 'kill $SERVER 2>/dev/null || true' EXIT
for _ in $(seq 50); do
  PORT=$(sed -n 's/.*udp:\/\/127\.0\.0\.1:\([0-9]*\).*/\1/p' "$OUT/server.txt")
  [ -n "$PORT" ] && break
  sleep 0.1
done

echo "== 100 Hz DMC over UDP for $DURATION s (log $OUT/hil.csv)"
"$PNEUMID" run --controller dmc --model fopdt-paper --io "udp://127.0.0.1:$PORT" \
  --setpoint "$SETPOINT" --duration "$DURATION" --period 0.01 --max-overruns -1 \
  --log "$OUT/hil.csv" --json --offline --plant ipa > "$OUT/hil.json"
kill -INT $SERVER; wait $SERVER || true
/usr/bin/python3 - "$OUT/hil.json" "$OUT/hil.csv" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
rows = sum(1 for l in open(sys.argv[2]) if l[0].isdigit())
print(f"samples {j['samples']}, log rows {rows}, overruns {j['overruns']}, "
      f"jitter p50/p99/max {j['jitter_p50_us']:.0f}/{j['jitter_p99_us']:.0f}/{j['jitter_max_us']:.0f} us, "
      f"compute p99 {j['compute_p99_us']:.0f} us; {j['scheduling']}")
print(f"{'metric':20s} {'real time (udp)':>16s} {'offline':>12s}")
for k in ['rise_time', 'overshoot_percent', 'settling_time', 'steady_state_error', 'iae', 'tv_u']:
    a, b = j['metrics'][k], j['offline_metrics'][k]
    print(f"{k:20s} {a if a is not None else float('nan'):16.6g} {b if b is not None else float('nan'):12.6g}")
PY

echo "== 1 kHz PID on the sim backend for 10 s"
"$PNEUMID" run --controller pid --model fopdt-paper --io sim --period 0.001 --duration 10 \
  --setpoint step:from=0,to=100,at=0.5 --max-overruns -1 --log "$OUT/sim1k.csv" --json > "$OUT/sim1k.json"
/usr/bin/python3 -c "
import json; j = json.load(open('$OUT/sim1k.json'))
print(f\"samples {j['samples']}, overruns {j['overruns']}, jitter p50/p99/max {j['jitter_p50_us']:.0f}/{j['jitter_p99_us']:.0f}/{j['jitter_max_us']:.0f} us, compute p50/p99/max {j['compute_p50_us']:.0f}/{j['compute_p99_us']:.0f}/{j['compute_max_us']:.0f} us; {j['scheduling']}\")"
