#!/usr/bin/env bash
# CLI tests of the real-time commands: run, experiment, plant-server.
# Usage: bash realtime_test.sh /path/to/pneumid   (cwd: a scratch/build directory)
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh" "$@"
SERVER_PID=""
cleanup() {  # called by lib.sh on exit
  if [ -n "$SERVER_PID" ]; then kill "$SERVER_PID" 2>/dev/null; wait "$SERVER_PID" 2>/dev/null; fi
}

start_server() {  # start_server [extra flags]; sets SERVER_PID and PORT
  # Empty the file here, not in the background job's redirection: that runs in the
  # child and can come after the loop below has read the previous server's port.
  : > "$TMP/server.txt"
  "$PNEUMID" plant-server --plant ipa --port 0 "$@" > "$TMP/server.txt" 2>&1 &
  SERVER_PID=$!
  for _ in $(seq 50); do
    PORT=$(sed -n 's/.*udp:\/\/127\.0\.0\.1:\([0-9]*\).*/\1/p' "$TMP/server.txt")
    [ -n "$PORT" ] && return 0
    sleep 0.1
  done
  die "plant-server did not start: $(cat "$TMP/server.txt")"
}
wait_rows() {  # wait_rows FILE N: until FILE holds N data rows (at most 20 s)
  for _ in $(seq 200); do
    [ -f "$1" ] && [ "$(data_rows "$1")" -ge "$2" ] && return 0
    sleep 0.1
  done
  fail "$1: fewer than $2 rows after 20 s"
}
stop_server() {
  kill -INT "$SERVER_PID"; wait "$SERVER_PID"; SERVER_PID=""
}

# --help everywhere: the shared real-time options under their canonical names
for c in run experiment; do
  check_help $c --io "--Ts,--period,--sample-time" --duration --log --json --safe-state --config
done
check_help plant-server --port "--Ts,--period,--sample-time"

# experiment: a data set with t,u,y that the identification reads
"$PNEUMID" experiment step --fast --duration 2 -o "$TMP/step.csv" > "$TMP/out.txt" || fail "experiment step"
[ "$(data_rows "$TMP/step.csv")" -eq 200 ] || fail "experiment rows: $(data_rows "$TMP/step.csv")"
grep -v '^#' "$TMP/step.csv" | head -1 | grep -qx 't,u,y' || fail "experiment header"
# A simulated linear plant's input is unbounded (as in control and run): a
# step from -5 to -2 was clipped to 0..100 % and recorded as u = 0, y = 0.
"$PNEUMID" experiment --fast --plant "tf:num=1,den=1 1" --input "step:from=-5,to=-2,at=0.5" \
  --duration 2 -o "$TMP/neg.csv" > /dev/null || fail "experiment on a linear plant"
grep -v '^#' "$TMP/neg.csv" | tail -1 | awk -F, '$2 != -2 || $3 > -1.9 {exit 1}' ||
  fail "experiment clipped the input of a linear plant: $(grep -v '^#' "$TMP/neg.csv" | tail -1)"
"$PNEUMID" experiment prbs --fast --duration 1 -o "$TMP/prbs.csv" --json > "$TMP/prbs.json" || fail "experiment prbs"
grep -q '"samples": 100' "$TMP/prbs.json" || fail "experiment prbs json"
"$PNEUMID" experiment staircase --fast --duration 1 -o "$TMP/stairs.mat" > /dev/null || fail "experiment .mat"
[ -s "$TMP/stairs.mat" ] || fail "no .mat written"
"$PNEUMID" identify "$TMP/step.csv" > "$TMP/id.txt" 2>&1 ||
  fail "identify cannot read the experiment data: $(cat "$TMP/id.txt")"
grep -q "reaction-curve" "$TMP/id.txt" || fail "identify of the experiment lists no model: $(head -c 500 "$TMP/id.txt")"

# closed loop through a plant server (hardware in the loop on 127.0.0.1)
start_server
"$PNEUMID" run --controller dmc --model fopdt-paper --io "udp://127.0.0.1:$PORT" \
  --setpoint step:from=0,to=100,at=0.2 --duration 1 --max-overruns -1 \
  --log "$TMP/udp.csv" --json > "$TMP/udp.json" || fail "run over udp: $(cat "$TMP/udp.json")"
for key in '"samples": 100' '"termination": "success"' '"jitter_p99_us"' '"jitter_max_us"' '"overruns"'; do
  grep -q "$key" "$TMP/udp.json" || fail "run --json lacks $key"
done
[ "$(data_rows "$TMP/udp.csv")" -eq 100 ] || fail "udp log rows: $(data_rows "$TMP/udp.csv")"
grep -q '^# timing: 100 samples' "$TMP/udp.csv" || fail "timing statistics missing from the log"
stop_server
grep -q "safe-state requests" "$TMP/server.txt" || fail "server summary"

# a load step on the server's plant (plant-server --load-step), the same step
# told to run for the metrics: the real-time loop over udp gives the metrics of
# the same scenario simulated offline (--offline applies the load itself)
start_server --load-step at=1.2,size=-10
"$PNEUMID" run --controller mpc --model fopdt-paper --io "udp://127.0.0.1:$PORT" \
  --setpoint step:from=0,to=40,at=0.2 --duration 2 --max-overruns -1 --load-step at=1.2,size=-10 \
  --offline --json > "$TMP/load.json" || fail "run with a load step over udp"
$PY - "$TMP/load.json" <<'PYEOF' || fail "udp load step metrics: $(cat "$TMP/load.json")"
import json, sys
j = json.load(open(sys.argv[1]))
m, o = j["metrics"], j["offline_metrics"]
assert m["load_peak_deviation"] < -5 and abs(m["load_peak_deviation"] - o["load_peak_deviation"]) < 0.5, (m, o)
assert m["load_recovery_time"] is not None and abs(m["load_recovery_time"] - o["load_recovery_time"]) <= 0.02
assert abs(m["iae"] - o["iae"]) <= 0.05 * o["iae"], (m["iae"], o["iae"])
PYEOF
stop_server
# the same load on the simulator backend
"$PNEUMID" run --controller mpc --model fopdt-paper --io sim --fast --duration 2 \
  --setpoint step:from=0,to=40,at=0.2 --load-step at=1.2,size=-10 --json > "$TMP/simload.json" ||
  fail "run --io sim --load-step"
$PY -c 'import json,sys; m=json.load(open(sys.argv[1]))["metrics"]; assert m["load_peak_deviation"] < -5, m' \
  "$TMP/simload.json" || fail "sim load step not applied: $(cat "$TMP/simload.json")"
expect_error "bad load step" "--load-step" run --fast --duration 0.1 --load-step at=-1,size=2
# With measurement noise the loop reproduces its offline simulation sample
# for sample: the controller starts at the first measurement in both (it
# started at 0 in the loop: MPC IAE 12.2296 against 12.2317 offline).
for c in mpc gpc; do
  "$PNEUMID" run --controller $c --model fopdt-paper --plant fopdt-paper --fast --duration 8 \
    --setpoint "staircase:levels=0;40;80;40,dwell=2" --noise 0.5 --offline --json \
    > "$TMP/noise_$c.json" || fail "run --noise ($c)"
  $PY -c 'import json,sys; j=json.load(open(sys.argv[1])); m, o = j["metrics"], j["offline_metrics"]; assert m["iae"] == o["iae"] and m["tv_u"] == o["tv_u"], (m["iae"], o["iae"])' \
    "$TMP/noise_$c.json" || fail "run --noise ($c) differs from --offline: $(cat "$TMP/noise_$c.json")"
done

# a server that stops answering: timeout fault, safe state, complete log, exit 3
start_server --stop-answering-after 30
"$PNEUMID" run --controller pid --model fopdt-paper --io "udp://127.0.0.1:$PORT" \
  --setpoint step:from=0,to=50,at=0 --duration 2 --max-overruns -1 --safe-state exhaust-open \
  --log "$TMP/timeout.csv" > "$TMP/timeout.out" 2> "$TMP/timeout.err"
rc=$?
[ $rc -eq 3 ] || fail "timeout exit status $rc"
grep -q "timeout" "$TMP/timeout.err" || fail "timeout not reported: $(cat "$TMP/timeout.err")"
grep -q "exhaust-open" "$TMP/timeout.err" || fail "safe state not reported"
[ "$(data_rows "$TMP/timeout.csv")" -eq 34 ] || fail "timeout log rows: $(data_rows "$TMP/timeout.csv")"
tail -1 "$TMP/timeout.csv" | grep -q ',timeout$' || fail "fault reason not in the last row"
grep -q '^# stop: failure: timeout' "$TMP/timeout.csv" || fail "fault not in the log header"
stop_server

# sensor range fault on the simulator
"$PNEUMID" run --controller pid --model fopdt-paper --io sim --fast --duration 3 \
  --setpoint step:from=0,to=100,at=0 --y-max 50 --log "$TMP/range.csv" > /dev/null 2> "$TMP/range.err"
[ $? -eq 3 ] || fail "range fault exit status"
grep -q "sensor-out-of-range" "$TMP/range.err" || fail "range fault message"
tail -1 "$TMP/range.csv" | grep -q ',sensor-out-of-range$' || fail "range fault not logged"

# SIGINT: safe state, complete log, exit 130
"$PNEUMID" run --controller pid --model fopdt-paper --io sim --duration 60 --no-realtime \
  --max-overruns -1 --log "$TMP/int.csv" > "$TMP/int.out" 2>&1 &
RUN_PID=$!
wait_rows "$TMP/int.csv" 1  # running (its handlers installed), also on a loaded machine
sleep 0.5
kill -INT $RUN_PID
wait $RUN_PID
rc=$?
[ $rc -eq 130 ] || fail "SIGINT exit status $rc"
rows=$(data_rows "$TMP/int.csv")
grep -q "^# stop: stopped: stopped by signal 2 (Interrupt) after $rows samples" "$TMP/int.csv" ||
  fail "SIGINT: log rows ($rows) differ from the samples run: $(grep '^# stop' "$TMP/int.csv")"

# kill -9: at most the last second (flush interval) is missing
"$PNEUMID" run --controller pid --model fopdt-paper --io sim --duration 60 --no-realtime \
  --max-overruns -1 --log "$TMP/kill.csv" > /dev/null 2>&1 &
RUN_PID=$!
wait_rows "$TMP/kill.csv" 1  # the first flush (1 s) has come
sleep 2
kill -9 $RUN_PID
wait $RUN_PID 2>/dev/null
rows=$(data_rows "$TMP/kill.csv")
[ "$rows" -ge 100 ] || fail "after kill -9 only $rows rows survived"

# bad input: clear errors, non-zero exit, no crash
"$PNEUMID" run --io serial --duration 1 2> "$TMP/e1" && fail "bad --io accepted"
grep -q "unknown backend" "$TMP/e1" || fail "bad --io message: $(cat "$TMP/e1")"
"$PNEUMID" run --io comedi:/dev/comedi_pneumid_missing --duration 1 2> "$TMP/e2" && fail "missing device accepted"
grep -q "/dev/comedi_pneumid_missing" "$TMP/e2" || fail "missing device message: $(cat "$TMP/e2")"
"$PNEUMID" run --io udp://127.0.0.1:1 --duration 1 2> "$TMP/e3" && fail "no server accepted"
grep -q "no answer from a plant server" "$TMP/e3" || fail "no-server message: $(cat "$TMP/e3")"
expect_error "--period 0" "--Ts: must be in [0.0001, 10], got 0" run --period 0 --duration 1
expect_error "--Ts 0" "--Ts: must be in [0.0001, 10], got 0" experiment step --Ts 0 --duration 1 -o "$TMP/x.csv"
expect_error "negative duration" "--duration: must be > 0, got -1" run --fast --duration -1
expect_error "max-overruns" "--max-overruns: must be an integer >= -1, got -2" run --fast --max-overruns -2
expect_error "prbs clock" "--clock: must be > 0, got 0" experiment prbs --fast --clock 0 -o "$TMP/x.csv"
"$PNEUMID" experiment step --io udp://127.0.0.1:9 --fast -o "$TMP/x.csv" 2> "$TMP/e5" && fail "--fast with udp accepted"
grep -q "fast" "$TMP/e5" || fail "--fast message"

# --Ts, --period and --sample-time name the same loop period.
for flag in --Ts --period --sample-time; do
  expect_ok "experiment $flag" experiment step --fast --duration 1 $flag 0.02 -o "$TMP/p.csv"
  [ "$(data_rows "$TMP/p.csv")" -eq 50 ] || fail "experiment $flag 0.02: $(data_rows "$TMP/p.csv") rows"
done

# Safe states: generic hold/release, the IPA's names as aliases; messages use the
# plant's names (the IPA: valves-closed/exhaust-open, a linear plant: hold/release).
"$PNEUMID" run --controller pid --model fopdt-paper --io sim --fast --duration 0.5 \
  --safe-state release --json > "$TMP/rel.json" || fail "--safe-state release"
grep -q '"safe_state": "exhaust-open"' "$TMP/rel.json" || fail "IPA release name: $(cat "$TMP/rel.json")"
"$PNEUMID" run --controller pid --model fopdt-paper --io sim --plant fopdt-paper --fast \
  --duration 0.5 --safe-state exhaust-open --json > "$TMP/rel2.json" || fail "--safe-state exhaust-open"
grep -q '"safe_state": "release"' "$TMP/rel2.json" || fail "generic release name: $(cat "$TMP/rel2.json")"
"$PNEUMID" run --controller pid --model fopdt-paper --io sim --plant fopdt-paper --fast \
  --duration 0.5 --log "$TMP/hold.csv" > /dev/null || fail "linear plant run"
# A simulated linear plant's input is unbounded, as in `control` (+-1e300:
# the clamp must be finite).
grep -q '^# safety: u in \[-1e+300, 1e+300\], .*safe state hold$' "$TMP/hold.csv" ||
  fail "safety header of a linear plant: $(grep '^# safety' "$TMP/hold.csv")"

# The settings mean the same in run as in control (one rule inference): --P --M
# --lambda all given is the explicit rule, otherwise they override shridhar-cooper.
"$PNEUMID" run --fast --duration 0.2 --P 50 --M 4 --lambda 1.5 --json > "$TMP/x.json" || fail "run explicit"
grep -q '"controller": "dmc P=50 M=4 lambda=1.5' "$TMP/x.json" || fail "run explicit: $(grep controller "$TMP/x.json")"
"$PNEUMID" run --fast --duration 0.2 --P 50 --json > "$TMP/y.json" || fail "run override"
grep -q '"controller": "dmc P=50 M=5 lambda=' "$TMP/y.json" || fail "run override: $(grep controller "$TMP/y.json")"
"$PNEUMID" run --controller mpc --fast --duration 0.2 --json > "$TMP/m.json" || fail "run mpc"
grep -q '"controller": "mpc P=126 M=5 lambda=.* disturbance=input' "$TMP/m.json" ||
  fail "run mpc: $(grep controller "$TMP/m.json")"
finish
