#!/usr/bin/env bash
# pneumid commission: the default twin end to end (files, JSON keys, the
# controller.toml that control, run and codegen take with --config), a
# variant twin, and the errors of a range out of reach and a short budget.
# Usage: bash commission_test.sh PNEUMID
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh" "$@"

"$PNEUMID" commission --help | grep -q -- "--budget" || fail "--help"

"$PNEUMID" commission --plant ipa -o "$TMP/c" --json --report > "$TMP/c.json"
rc=$?
# 0: the specification is met (4 would be a controller that misses it).
[ "$rc" -eq 0 ] || fail "commission on the default twin exited $rc: $(head -c 600 "$TMP/c.json")"
for f in data.csv models.json controller.toml verification.csv experiment.png verification.png \
  c/pneumid_ctrl.c c/pneumid_ctrl.h report.html; do
  [ -s "$TMP/c/$f" ] || fail "commission did not write $f"
done
# The report: every section and one figure per verification plus the two model figures.
for s in "Experiment" "Models" "Verification on the plant" "held-out"; do
  grep -q "$s" "$TMP/c/report.html" || fail "report.html: no '$s'"
done
[ "$(grep -c "<svg" "$TMP/c/report.html")" -ge 3 ] || fail "report.html: fewer than 3 figures"
$PY - "$TMP/c.json" <<'PYEOF' || fail "commission JSON"
import json, sys
j = json.load(open(sys.argv[1]))
for k in ("experiment", "models", "chosen_model", "controller", "verification", "passed",
          "limits", "suggestions", "plant_time"):
    assert k in j, k
e = j["experiment"]
assert e["duration"] <= 120.0 + 0.02, e["duration"]
# The default twin: tau about 0.21 s behind its sensor filter, range about 0..192 N.
assert 0.1 < e["probe"]["time_constant"] < 0.4, e["probe"]
assert 150 < e["sweep"]["reachable_max"] < 250, e["sweep"]
v = j["verification"]
for k in ("overshoot_percent", "settling_time", "iae", "steps", "worst_overshoot_step"):
    assert k in v, k
assert len(v["steps"]) >= 8, len(v["steps"])
# The chosen model is the best held-out fit among the usable ones, and it holds.
fits = {m["method"]: m["validation_fit_percent"] for m in j["models"]}
assert fits[j["chosen_model"]] > 90.0, fits
# Modulation across the valves' dead bands, behind the chord of the map
# inside them: the loop meets the 5 % specification on the plant, small
# steps included (8-12 % of the range), at the first design, which aims at
# 1.25 times the fastest robust design's response time (that design, whose
# overshoot on the model is at the specification, overshot 15.7 % on a
# small step).
assert v["overshoot_percent"] <= 5.0, v["overshoot_percent"]
a = j["attempts"]
assert len(a) == 1 and a[0]["passed"], [(b["aggressiveness"], b["passed"]) for b in a]
span = e["range"][1] - e["range"][0]
small = [s for s in v["steps"] if s["time"] > 0 and abs(s["to"] - s["from"]) < 0.15 * span]
assert len(small) >= 3, [(s["from"], s["to"]) for s in v["steps"]]
# The MPC's measurement noise is the noise measured at rest.
assert 0.03 < e["noise_std"] < 0.15, e["noise_std"]
# The estimation record begins at the sweep's steady state (193 N at 100 %),
# so the Hammerstein's map holds at the low end (before, its simulation
# started at rest at the first level, and the map came out 11 N too high at
# 1 % duty: a 0.58 N cycle at 10 N failed the verification).
assert j["chosen_model"] == "hammerstein", j["chosen_model"]
models = json.load(open(sys.argv[1].replace("c.json", "c/models.json")))["models"]
ham = next(m for m in models if m["method"] == "hammerstein")
assert abs(ham["input_map"]["y"][0]) < 2.0, ham["input_map"]
# Knots at the ends of the valves' gaps (0:15 and 85:100 %), the corners of
# the actuator's map: f(85 %) within 5 N of the twin's 135 N.
u, f = ham["input_map"]["u"], ham["input_map"]["y"]
assert 15.0 in u and 85.0 in u, u
assert abs(f[u.index(85.0)] - 135.0) < 5.0, (u, f)
# One steady output and ripple per excitation level.
levels = len(e["estimation_levels"]) + len(e["validation_levels"])
assert len(e["level_outputs"]) == len(e["level_ripples"]) == levels, levels
PYEOF
# One sample per PWM period (300 Hz), and the Kalman filter's measurement
# variance in the configuration.
grep -q '^period = 0.00333333' "$TMP/c/controller.toml" || fail "controller.toml: period $(grep period "$TMP/c/controller.toml")"
grep -q '^measurement_noise = 0.00' "$TMP/c/controller.toml" || fail "controller.toml: no measurement_noise"
grep -q '^response_time = 0.0' "$TMP/c/controller.toml" || fail "controller.toml: no response_time (1.25 x the fastest design's)"

# The configuration runs as written: control, codegen and run.
"$PNEUMID" control --config "$TMP/c/controller.toml" --setpoint "staircase:levels=10 50 100 150 180 120 60 10,dwell=2" \
  --duration 18 --load-step at=17,size=-15 --json > "$TMP/ctl.json" || fail "control --config"
$PY - "$TMP/ctl.json" <<'PYEOF' || fail "control --config metrics"
import json, sys
j = json.load(open(sys.argv[1]))
assert "sigma-delta" in j["controller"], j["controller"]
assert j["overshoot_percent"] < 6.0, j["overshoot_percent"]
assert all(s["settled"] for s in j["steps"]), j["steps"]
PYEOF
# IAE against the paper's DMC on the same scenario (target 0.7 x; 0.70
# measured, 0.86 before the chord); without modulation ('none') the loop
# cycles at 150 N, inside the exhaust's dead band.
"$PNEUMID" control --controller dmc --model fopdt-paper --rule shridhar-cooper --plant ipa \
  --setpoint "staircase:levels=10 50 100 150 180 120 60 10,dwell=2" --duration 18 \
  --load-step at=17,size=-15 --json > "$TMP/dmc.json" || fail "paper DMC"
"$PNEUMID" control --config "$TMP/c/controller.toml" --input-gaps none \
  --setpoint "staircase:levels=10 50 100 150 180 120 60 10,dwell=2" --duration 18 \
  --load-step at=17,size=-15 --json > "$TMP/none.json" || fail "control --input-gaps none"
$PY - "$TMP/ctl.json" "$TMP/dmc.json" "$TMP/none.json" <<'PYEOF' || fail "IAE and --input-gaps none"
import json, sys
ctl, dmc, none = (json.load(open(f)) for f in sys.argv[1:4])
assert ctl["iae"] <= 0.75 * dmc["iae"], (ctl["iae"], dmc["iae"])
assert "sigma-delta" not in none["controller"], none["controller"]
at150 = lambda j: next(s["ripple"] for s in j["steps"] if abs(s["to"] - 150) < 1e-9)
assert at150(none) > 2 * at150(ctl), (at150(none), at150(ctl))
PYEOF
"$PNEUMID" codegen --config "$TMP/c/controller.toml" -o "$TMP/gen" > "$TMP/gen.txt" || fail "codegen --config"
grep -q "sigma-delta" "$TMP/gen.txt" "$TMP"/gen/*.c 2>/dev/null || fail "codegen: no modulator layer"
"$PNEUMID" run --config "$TMP/c/controller.toml" --fast --duration 2 --setpoint "step:from=0,to=100,at=0.2" --json \
  > "$TMP/run.json" || fail "run --config"

# A twin of other valves and supply: the same command, no hand tuning.
sed -e 's/^inlet_conductance = .*/inlet_conductance = 0.8e-8/' -e 's/^pressure = 0.6e6 /pressure = 0.5e6 /' \
  "$SRC/config/ipa_default.toml" > "$TMP/variant.toml"
"$PNEUMID" commission --plant ipa --plant-config "$TMP/variant.toml" -o "$TMP/v" --json > "$TMP/v.json"
rc=$?
[ "$rc" -eq 0 ] || [ "$rc" -eq 4 ] || fail "commission on the variant exited $rc"
$PY -c 'import json,sys; j=json.load(open(sys.argv[1])); assert j["verification"]["steps"], j' "$TMP/v.json" \
  || fail "variant JSON"

# The chamber-lag twin: inside the inlet valve's gap (about 10 N) the
# modulation alone ripples by 0.7-0.9 N in open loop, above twice the
# sensor's noise; the verification allows 1.25 times what the experiment's
# levels showed there, and judges the overshoot beyond half the ripple.
"$PNEUMID" commission --plant ipa --plant-config "$SRC/config/ipa_chamber_lag.toml" -o "$TMP/cl" \
  --json > "$TMP/cl.json" || fail "commission on the chamber-lag twin exited $?: $(head -c 600 "$TMP/cl.json")"
$PY - "$TMP/cl.json" "$TMP/cl/controller.toml" <<'PYEOF' || fail "chamber-lag JSON"
import json, sys
j = json.load(open(sys.argv[1]))
e = j["experiment"]
gap = [r for y, r in zip(e["level_outputs"], e["level_ripples"]) if 5 < y < 14]
assert gap and max(gap) > 2 * e["noise_peak_to_peak"], (gap, e["noise_peak_to_peak"])
assert any(s["to"] < 12 and s["time"] > 0 for s in j["verification"]["steps"]), j["verification"]
v = j["verification"]
assert v["overshoot_judged_percent"] <= min(v["overshoot_percent"], 5.0), v["overshoot_judged_percent"]
# Its softer designs fail and the peak of the first design (aggressiveness
# 0.5) is mostly the ripple: the fastest design is tried once, and kept (the
# last attempt) only for an IAE at least 5 % lower with an overshoot beyond
# half the ripple within 80 % of the specification (it is kept here: 1.47 %,
# IAE 31.3 against 39.1).
a = j["attempts"]
seen = [(b["aggressiveness"], b["passed"], round(b["overshoot_judged_percent"], 2), round(b["iae"], 1)) for b in a]
half = [b for b in a if b["aggressiveness"] == 0.5]
fast = [b for b in a if b["aggressiveness"] == 1.0]
assert half and half[0]["passed"] and fast and fast[0]["passed"], seen
assert all(not b["passed"] for b in a if b["aggressiveness"] < 0.5), seen
better = (fast[0]["iae"] < 0.95 * half[0]["iae"] and
          fast[0]["overshoot_judged_percent"] <= 0.8 * 5.0)
assert a[-1]["aggressiveness"] == (1.0 if better else 0.5), seen
assert better, seen
kept = "aggressiveness = %g" % a[-1]["aggressiveness"]
assert kept in open(sys.argv[2]).read().splitlines(), ("controller.toml: not the kept design", kept)
# Softening stops at the first softer design that fails on its settling (a
# softer one would settle later still), and the runs stay within the budget.
assert len([b for b in a if b["aggressiveness"] < 0.5]) == 1, seen
assert j["plant_time"] <= 120.0 + 1e-6, j["plant_time"]
PYEOF

# A GPC has no tuning to specifications of its own: it runs the horizons and
# move suppression of the DMC's auto design with the T filter A, written
# explicitly, and its configuration runs as written.
"$PNEUMID" commission --plant ipa --controller gpc -o "$TMP/g" --json > "$TMP/g.json"
rc=$?
[ "$rc" -eq 0 ] || [ "$rc" -eq 4 ] || fail "commission --controller gpc exited $rc"
for k in 'type = "gpc"' 'rule = "explicit"' 't_filter = "A"' '^P = ' '^lambda = '; do
  grep -q "$k" "$TMP/g/controller.toml" || fail "gpc controller.toml: no '$k'"
done
# Its first design aims at 1.25 x the DMC's fastest robust response time, as
# the MPC's and DMC's do (from the DMC's fastest design itself: 13.8 %).
$PY - "$TMP/g.json" <<'PYEOF' || fail "gpc first design"
import json, sys
j = json.load(open(sys.argv[1]))
first = j["attempts"][0]
assert first["passed"] and first["overshoot_percent"] < 10.0, first
assert len(j["attempts"]) <= 2, [a["overshoot_percent"] for a in j["attempts"]]
PYEOF
"$PNEUMID" control --config "$TMP/g/controller.toml" --setpoint "staircase:levels=20 120 60,dwell=1.5" \
  --duration 4.5 --json > "$TMP/gctl.json" || fail "control --config (gpc)"
$PY - "$TMP/gctl.json" <<'PYEOF' || fail "gpc control metrics"
import json, sys
j = json.load(open(sys.argv[1]))
assert j["controller"].startswith("gpc"), j["controller"]
assert j["overshoot_percent"] < 10.0 and j["settled"], (j["overshoot_percent"], j["settled"])
PYEOF

# Errors: a range out of reach names the reachable one; a short budget says what it needs.
out=$("$PNEUMID" commission --plant ipa --range 10:400 -o "$TMP/e1" 2>&1)
[ $? -eq 1 ] || fail "unreachable range: exit status"
echo "$out" | grep -q "cannot be reached: the output reaches" || fail "unreachable range: $out"
out=$("$PNEUMID" commission --plant ipa --budget 5 -o "$TMP/e2" 2>&1)
[ $? -eq 1 ] || fail "short budget: exit status"
echo "$out" | grep -q "too short" || fail "short budget: $out"
# A budget too short for even the probe says so (it blamed an integrating
# or unstable plant, "last change nan"), and no summary line prints nan.
out=$("$PNEUMID" commission --plant ipa --budget 0.001 -o "$TMP/e3" 2>&1)
[ $? -eq 1 ] || fail "tiny budget: exit status"
echo "$out" | grep -q "too short to probe the plant" || fail "tiny budget: $out"
echo "$out" | grep -qi "nan" && fail "tiny budget prints nan: $out"
# A linear plant slower than the verification's dwell: its unsettled steps
# are not called a cycling loop (ripple).
out=$("$PNEUMID" commission --plant "sopdt:K=1,tau1=1,tau2=0.3,theta=0.1" --u-min 0 --u-max 10 \
  -o "$TMP/e4" 2>/dev/null)
echo "$out" | grep -q "settling not reached" || fail "slow plant: $out"
echo "$out" | grep -q "the loop cycles" && fail "slow plant called cycling: $out"
echo "$out" | grep -q "worst settling not settled" || fail "slow plant summary: $out"
# An unstable plant: stopped within seconds of the probe step, the reason on
# stderr, no probe figures of NaN on stdout, the input back at its lowest.
out=$("$PNEUMID" commission --plant "tf:num=0.1,den=1 -1.05,Ts=0.01" --u-min 0 --u-max 10 \
  -o "$TMP/e4" 2>"$TMP/e4.err")
[ $? -eq 1 ] || fail "unstable plant: exit status"
grep -q "the output diverges after an input step from 0 to 5" "$TMP/e4.err" ||
  fail "unstable plant: $(cat "$TMP/e4.err")"
echo "$out" | grep -q "stopped in the probe step" || fail "unstable plant: stdout $out"
echo "$out" | grep -qi "nan" && fail "unstable plant: NaN on stdout: $out"
tail -1 "$TMP/e4/data.csv" | awk -F, '$1 <= 6 && $2 == 0 { ok = 1 } END { exit !ok }' ||
  fail "unstable plant: data end $(tail -1 "$TMP/e4/data.csv") (not at u = 0 within 6 s)"
# A plant that declares no input range (a linear model) needs one: the
# message names the flags.
expect_error "no input range" "give it where the plant declares none (--u-min and --u-max" \
  commission --plant "tf:num=1,den=1 1" -o "$TMP"
out=$("$PNEUMID" commission --plant ipa --spec overshoot=x -o "$TMP/e3" 2>&1)
[ $? -ne 0 ] || fail "bad --spec accepted"
echo "$out" | grep -q "overshoot" || fail "bad --spec message: $out"

# Over UDP against a plant server (the same twin in another process), stepped
# as fast as it answers, at the simulator's loop period (one PWM period): the
# same stages and the same verification within noise, the load step included
# (an output disturbance over the backend too) and each run started from rest.
SERVER_PID=""
cleanup() { [ -n "$SERVER_PID" ] && kill "$SERVER_PID" 2>/dev/null; }
start_server() {  # start_server PLANT: serves it at one PWM period; sets SERVER_PID and PORT
  : > "$TMP/server.txt"
  "$PNEUMID" plant-server --plant "$1" --port 0 --Ts 0.0033333333333 > "$TMP/server.txt" 2>&1 &
  SERVER_PID=$!
  PORT=""
  for _ in $(seq 50); do
    PORT=$(sed -n 's/.*udp:\/\/127\.0\.0\.1:\([0-9]*\).*/\1/p' "$TMP/server.txt")
    [ -n "$PORT" ] && break
    sleep 0.1
  done
  [ -n "$PORT" ] || fail "plant-server did not start: $(cat "$TMP/server.txt")"
}
start_server ipa
# Neither --Ts nor --input-gaps: the server's period and gaps are taken.
"$PNEUMID" commission --io "udp://127.0.0.1:$PORT" --fast -o "$TMP/u" --json \
  > "$TMP/u.json" 2> "$TMP/u.err"
rc=$?
[ "$rc" -eq 0 ] || [ "$rc" -eq 4 ] || fail "commission over udp exited $rc"
grep -q "reports no input gaps" "$TMP/u.err" && fail "udp: warned $(cat "$TMP/u.err")"
grep -q '^period = 0.0033333333333' "$TMP/u/controller.toml" ||
  fail "udp: not the server's period: $(grep period "$TMP/u/controller.toml")"
grep -q '^input_gaps = "0:15,85:100"' "$TMP/u/controller.toml" ||
  fail "udp: not the server's gaps: $(grep input_gaps "$TMP/u/controller.toml")"
$PY - "$TMP/u.json" "$TMP/c.json" <<'PYEOF' || fail "commission over udp JSON"
import json, sys
u, s = (json.load(open(p)) for p in sys.argv[1:3])
# The same twin: the probe's time constant and the reachable range agree with the simulator's.
assert abs(u["experiment"]["probe"]["time_constant"] - s["experiment"]["probe"]["time_constant"]) < 0.03
assert abs(u["experiment"]["sweep"]["reachable_max"] - s["experiment"]["sweep"]["reachable_max"]) < 5
assert u["verification"]["steps"], u
uv, sv = u["verification"], s["verification"]
assert abs(uv["overshoot_percent"] - sv["overshoot_percent"]) < 1.5, (uv["overshoot_percent"], sv["overshoot_percent"])
assert abs(uv["iae"] / sv["iae"] - 1.0) < 0.15, (uv["iae"], sv["iae"])
assert abs(uv["load_peak_deviation"] - sv["load_peak_deviation"]) < 1.5, (uv["load_peak_deviation"], sv["load_peak_deviation"])
assert sv["load_peak_deviation"] < -10.0, sv["load_peak_deviation"]
PYEOF
grep -q 'backend = "udp://127.0.0.1:' "$TMP/u/controller.toml" || fail "udp controller.toml: no backend"
# A given period other than the server's: the error names the server's.
out=$("$PNEUMID" commission --io "udp://127.0.0.1:$PORT" --Ts 0.01 --fast -o "$TMP/u1" 2>&1)
[ $? -eq 1 ] || fail "udp with another period: exit status"
echo "$out" | grep -q "its plant runs at Ts = 0.0033333333333 s, not 0.01 s" ||
  fail "udp with another period: $out"
kill "$SERVER_PID"; wait "$SERVER_PID" 2>/dev/null; SERVER_PID=""

# A positioning drive behind the server: the server describes its actuator
# (a signed command, the stroke, integrating), so commission takes the
# integrating plant's route over UDP as on the simulator.
start_server ipa-position
"$PNEUMID" commission --io "udp://127.0.0.1:$PORT" --fast -o "$TMP/up" --json \
  > "$TMP/up.json" 2> "$TMP/up.err" || fail "commission of a positioning drive over udp: $(cat "$TMP/up.err")"
$PY - "$TMP/up.json" <<'PYEOF' || fail "commission of a positioning drive over udp JSON"
import json, sys
j = json.load(open(sys.argv[1]))
assert j["chosen_model"] == "integrator", j["chosen_model"]
assert "overshoot <= 2 %, settling <= 1 s" in j["message"], j["message"]  # a drive's targets
assert j["controller"]["type"] == "pid", j["controller"]
v = j["verification"]
assert v["passed"] and v["u_min"] < -50.0, (v["passed"], v["u_min"])  # it retracts
# Every step ends within 0.1 mm, as the verification judges it. (The final
# segment's error, after the load step, moves with replies that come late on
# a busy machine: 0.06-0.12 mm.)
assert abs(v["worst_steady_state_error"]) <= 1e-4, v["worst_steady_state_error"]
PYEOF
grep -q '^input_gaps = "-100:-91,-9:0,0:9,91:100"' "$TMP/up/controller.toml" ||
  fail "udp position: not the server's gaps: $(grep input_gaps "$TMP/up/controller.toml")"
kill "$SERVER_PID"; wait "$SERVER_PID" 2>/dev/null; SERVER_PID=""

# Ctrl-C in the middle of the experiment: exit 130, the plant at its lowest
# input, the data so far written.
"$PNEUMID" commission --plant ipa --plant-config "$SRC/config/ipa_slow_valves.toml" --budget 600 \
  --io sim -o "$TMP/s" > "$TMP/s.txt" 2>&1 &
pid=$!
sleep 0.5
kill -INT "$pid"
wait "$pid"
rc=$?
[ "$rc" -eq 130 ] || [ "$rc" -eq 0 ] || [ "$rc" -eq 4 ] || fail "Ctrl-C: exit $rc"
if [ "$rc" -eq 130 ]; then
  [ -s "$TMP/s/data.csv" ] || fail "Ctrl-C: no data.csv"
  grep -q "stopped on request" "$TMP/s.txt" || fail "Ctrl-C: $(cat "$TMP/s.txt")"
fi
finish
