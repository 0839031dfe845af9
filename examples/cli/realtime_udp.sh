#!/usr/bin/env bash
# A real-time MPC loop against a plant served over UDP (hardware-in-the-loop
# stand-in), on the loopback interface:
#
#   pneumid plant-server   serves the IPA simulator on udp://127.0.0.1:PORT
#   pneumid run            runs the controller every 10 ms against it, with
#                          safety limits, a log and timing statistics
#
# The server is started in the background and stopped with SIGINT at the end
# (or when the script fails). On a real rig, --io comedi:/dev/comedi0 takes
# the place of --io udp://... (docs/realtime.md).
#
# Usage: bash examples/cli/realtime_udp.sh [PNEUMID] [OUTDIR]
# Writes OUTDIR/server.txt, run.json and run.csv (the log, one row per sample).
source "$(dirname "${BASH_SOURCE[0]}")/common.sh" "$@"

SERVER_PID=""
stop_server() {
  if [ -n "$SERVER_PID" ]; then
    kill -INT "$SERVER_PID" 2>/dev/null || true
    wait "$SERVER_PID" 2>/dev/null || true
    SERVER_PID=""
  fi
}
# On any exit: stop the server, then remove a temporary OUT (common.sh's trap).
if [ -z "${2:-}" ]; then
  trap 'stop_server; rm -rf "$OUT"' EXIT
else
  trap stop_server EXIT
fi

# 1. The plant server on a free port (--port 0); it prints the address.
"$PNEUMID" plant-server --plant ipa --Ts 0.01 --port 0 > "$OUT/server.txt" 2>&1 &
SERVER_PID=$!
PORT=""
for _ in $(seq 50); do
  PORT=$(sed -n 's/.*udp:\/\/127\.0\.0\.1:\([0-9]*\).*/\1/p' "$OUT/server.txt")
  [ -n "$PORT" ] && break
  sleep 0.1
done
[ -n "$PORT" ] || { echo "plant-server did not start: $(cat "$OUT/server.txt")" >&2; exit 1; }
cat "$OUT/server.txt"

# 2. Two seconds of MPC at 100 Hz through the server: a 0 -> 40 N step at
#    0.2 s. --offline also simulates the same scenario without the network,
#    for comparison; --max-overruns -1 keeps a busy machine's late wake-ups
#    from stopping the run (they are counted).
# A machine busy with other work may answer a datagram late: the [udp]
# section lets the loop miss up to 20 replies in a row before it stops.
printf '[udp]\nmax_missed = 20\n' > "$OUT/udp.toml"
"$PNEUMID" run --controller mpc --model fopdt-paper --io "udp://127.0.0.1:$PORT" --Ts 0.01 \
  --setpoint step:from=0,to=40,at=0.2 --duration 2 --log "$OUT/run.csv" \
  --max-overruns -1 --offline --plant ipa --config "$OUT/udp.toml" --json > "$OUT/run.json"

# 3. Stop the server; it exits 0 on SIGINT.
kill -INT "$SERVER_PID"
rc=0
wait "$SERVER_PID" || rc=$?
SERVER_PID=""
check "$rc == 0" "plant-server stopped cleanly"

echo "samples $(json "$OUT/run.json" "j['samples']"), overruns $(json "$OUT/run.json" "j['overruns']")," \
  "jitter p99 $(json "$OUT/run.json" "j['jitter_p99_us']") us," \
  "compute p99 $(json "$OUT/run.json" "j['compute_p99_us']") us"
echo "IAE real time $(json "$OUT/run.json" "round(j['metrics']['iae'], 3)") N s," \
  "offline $(json "$OUT/run.json" "round(j['offline_metrics']['iae'], 3)") N s"
check "j['termination'] == 'success' and j['samples'] == 200" "200 samples, no fault" "$OUT/run.json"
rows=$(grep -v '^#' "$OUT/run.csv" | tail -n +2 | wc -l)
check "$rows == 200" "every sample in the log"
# Over UDP the loop sees what the offline simulation sees unless a reply
# came late (a stale sample); the metrics agree within a few percent.
check "abs(j['metrics']['iae'] - j['offline_metrics']['iae']) < 0.05 * j['offline_metrics']['iae']" \
  "IAE within 5 % of the offline simulation" "$OUT/run.json"
check "abs(j['metrics']['steady_state_error']) < 1.0" "at 40 N within 1 N at the end" "$OUT/run.json"
if [ -n "${2:-}" ]; then echo "outputs in $OUT"; fi
echo "realtime_udp: all checks passed"
