#!/usr/bin/env bash
# pneumid control: the paper's conventional and modified DMC on the nominal
# FOPDT (docs/paper.md, reference value 6), --compare, CSV output, the IPA plant
# with duty bounds, and error handling. Usage: bash control_test.sh PNEUMID
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh" "$@"
tmp=$TMP

out=$("$PNEUMID" control --controller dmc --model fopdt-paper --plant fopdt-paper --Ts 0.01 \
      --P 126 --M 5 --lambda 2.25 --setpoint step:from=0,to=1,at=0 --duration 2 --json) \
  || fail "control dmc exited non-zero"
echo "$out" | $PY -c '
import json, sys
j = json.load(sys.stdin)
for k in ("rise_time", "overshoot_percent", "settling_time", "steady_state_error", "iae", "u_min", "u_max", "first_move", "ise", "itae", "tv_u"):
    assert k in j, k
assert abs(j["first_move"] - 0.672) < 1e-3, j["first_move"]
assert abs(j["rise_time"] - 0.110) <= 0.01, j["rise_time"]
assert abs(j["overshoot_percent"] - 2.0) < 0.1, j["overshoot_percent"]
assert abs(j["settling_time"] - 0.23) <= 0.01, j["settling_time"]
assert abs(j["steady_state_error"]) < 1e-9, j["steady_state_error"]
assert j["settings"]["rule"] == "explicit"
' || fail "explicit M=5 metrics: $out"

out=$("$PNEUMID" control --controller dmc --model fopdt-paper --Ts 0.01 --setpoint step:from=0,to=1,at=0 \
      --duration 2 --compare --json -o "$tmp/fig6.csv") || fail "--compare exited non-zero"
echo "$out" | $PY -c '
import json, sys
runs = json.load(sys.stdin)["compare"]
assert [r["label"] for r in runs] == ["shridhar-cooper", "paper-modified"], runs
assert abs(runs[1]["first_move"] - 0.761) < 1e-3, runs[1]["first_move"]
assert abs(runs[1]["overshoot_percent"] - 3.6) < 0.1, runs[1]["overshoot_percent"]
assert runs[1]["settings"]["M"] == 10 and runs[1]["settings"]["lambda"] == 1.92
' || fail "--compare JSON: $out"
head -1 "$tmp/fig6.csv" | grep -q "^t,r,y_shridhar-cooper" || fail "CSV header: $(head -1 "$tmp/fig6.csv")"
[ "$(wc -l < "$tmp/fig6.csv")" -eq 201 ] || fail "CSV rows: $(wc -l < "$tmp/fig6.csv")"

# Text table; GPC and PID run too.
"$PNEUMID" control --controller gpc --model arx-paper --Ts 0.01 --setpoint step:from=0,to=1,at=0.1 \
  --duration 2 | grep -q "rise time" || fail "gpc text output"
"$PNEUMID" control --controller pid --model fopdt-paper --plant arx-paper --Ts 0.01 \
  --setpoint step:from=0,to=1,at=0.1 --duration 3 --json | $PY -c '
import json, sys
j = json.load(sys.stdin)
assert abs(j["steady_state_error"]) < 1e-3, j
' || fail "pid"

# Nonlinear IPA simulator, QDMC with the duty cycle bounded to 0..100 %, load step.
out=$("$PNEUMID" control --controller dmc --model fopdt-paper --plant ipa --Ts 0.01 --u-min 0 --u-max 100 \
      --constrained --setpoint "staircase:levels=0 40 80,dwell=2" --duration 6 --load-step at=5,size=-10 --json) \
  || fail "ipa exited non-zero"
echo "$out" | $PY -c '
import json, sys
j = json.load(sys.stdin)
assert j["u_min"] >= 0 and j["u_max"] <= 100, (j["u_min"], j["u_max"])
assert abs(j["steady_state_error"]) < 2.0, j["steady_state_error"]
assert j["load_peak_deviation"] < -5, j["load_peak_deviation"]
# The summary reports the worst step; steps[0] keeps the first step.
steps = j["steps"]
assert len(steps) == 2, steps
worst = max(range(2), key=lambda i: steps[i]["overshoot_percent"])
assert j["overshoot_percent"] == steps[worst]["overshoot_percent"] and j["worst_overshoot_step"] == worst, j
assert j["settled"] == all(s["settled"] for s in steps), j
if j["settled"]:
    assert j["settling_time"] == max(s["settling_time"] for s in steps), j
assert j["rise_time"] == steps[0]["rise_time"], j
' || fail "ipa metrics: $out"

# The plant's input range applies by default: the IPA's duty stays within 0..100 %
# without --u-min/--u-max (unclamped, this loop asks for 213 %).
"$PNEUMID" control --controller dmc --model fopdt-paper --plant ipa --rule shridhar-cooper --Ts 0.01 \
  --setpoint step:from=20,to=100,at=0.5 --duration 4 --json | $PY -c '
import json, sys
j = json.load(sys.stdin)
assert j["u_min"] >= 0 and j["u_max"] <= 100, (j["u_min"], j["u_max"])
assert j["u_max"] > 99, j["u_max"]
' || fail "ipa default input range"
expect_error "u-min above the plant range" "above --u-max 100" \
  control --controller dmc --model fopdt-paper --plant ipa --Ts 0.01 --u-min 150 \
  --setpoint step:from=0,to=50,at=0.1 --duration 1

# State-space MPC (Kalman filter, input disturbance model by default) on the same loop:
# within the duty range, the QP on the plant's limits, offset-free at the end.
"$PNEUMID" control --controller mpc --model fopdt-paper --plant ipa --rule shridhar-cooper --Ts 0.01 \
  --setpoint step:from=20,to=100,at=0.5 --duration 4 --json | $PY -c '
import json, sys
j = json.load(sys.stdin)
m = j["metrics"] if "metrics" in j else j
assert m["u_min"] >= 0 and m["u_max"] <= 100, (m["u_min"], m["u_max"])
assert abs(m["steady_state_error"]) < 1.0, m["steady_state_error"]
assert "mpc P=126 M=5" in json.dumps(j) and "disturbance=input" in json.dumps(j)
' || fail "mpc on the ipa"

# Errors.
err=$("$PNEUMID" control --controller lqg --model fopdt-paper --Ts 0.01 --setpoint step:from=0,to=1,at=0 \
      --duration 1 2>&1 >/dev/null) && fail "unknown controller accepted"
echo "$err" | grep -q "dmc, gpc, pid, mpc" || fail "unknown controller message: $err"
"$PNEUMID" control --model fopdt-paper --Ts 0.01 --setpoint step:from=0,to=1,at=0 --duration 1 \
  --load-step at=x >/dev/null 2>&1 && fail "bad load step accepted"
"$PNEUMID" control --model fopdt-paper --Ts 0.01 --setpoint bogus --duration 1 >/dev/null 2>&1 \
  && fail "bad set-point accepted"
check_help control --compare "--Ts,--sample-time" --plot "-o,--output"
expect_error "zero Ts" "--Ts: must be > 0, got 0" control --model fopdt-paper --Ts 0 \
  --setpoint step:from=0,to=1,at=0 --duration 1
expect_error "negative duration" "--duration: must be > 0, got -2" control --model fopdt-paper \
  --setpoint step:from=0,to=1,at=0 --duration -2
expect_error "negative lambda" "--lambda: must be >= 0, got -1" control --model fopdt-paper \
  --setpoint step:from=0,to=1,at=0 --duration 1 --lambda -1

# --plot: units on both axes (force N and duty % for the IPA), the controller and
# its settings in the legend, a title saying what was run (the SVG's <title>/<desc>).
expect_ok "plot ipa" control --controller dmc --model fopdt-paper --plant ipa --Ts 0.01 \
  --u-min 0 --u-max 100 --setpoint step:from=0,to=50,at=0.1 --duration 1 --plot "$tmp/ipa.svg"
check_svg "$tmp/ipa.svg"
for text in "Force F [N]" "Duty cycle u [%]" "Time t [s]" "DMC on ipa (model fopdt-paper, Ts = 0.01 s)" \
  "DMC shridhar-cooper (P="; do
  check_output "plot ipa" "$text" "$tmp/ipa.svg"
done
expect_ok "plot generic" control --controller pid --model fopdt-paper --plant arx-paper --Ts 0.01 \
  --setpoint step:from=0,to=1,at=0.1 --duration 1 --plot "$tmp/pid.png"
check_png "$tmp/pid.png"
expect_ok "plot generic svg" control --controller pid --model fopdt-paper --plant arx-paper --Ts 0.01 \
  --setpoint step:from=0,to=1,at=0.1 --duration 1 --plot "$tmp/pid.svg"
for text in "Output y" "Input u" "PID on arx-paper" "PID simc (Kc="; do
  check_output "plot generic" "$text" "$tmp/pid.svg"
done
expect_ok "plot compare" control --controller dmc --model fopdt-paper --Ts 0.01 \
  --setpoint step:from=0,to=1,at=0 --duration 1 --compare --plot "$tmp/cmp.svg"
check_output "plot compare" "DMC paper-modified (P=126, M=10, lambda=1.92)" "$tmp/cmp.svg"

# JSON keys are a contract: the run, its settings and its metrics (ClosedLoopMetrics::ToJson).
expect_ok "json keys" control --controller dmc --model fopdt-paper --Ts 0.01 \
  --setpoint "staircase:levels=0 1,dwell=0.5" --duration 1 --json
check_json "json keys" "list(j) == ['label', 'controller', 'plant', 'settings', 'rise_time', 'overshoot_percent', 'settling_time', 'steady_state_error', 'first_move', 'settling_band', 'settled', 'worst_overshoot_step', 'overshoot_beyond_ripple_percent', 'worst_settling_step', 'worst_steady_state_error', 'worst_steady_state_error_step', 'iae', 'ise', 'itae', 'tv_u', 'u_min', 'u_max', 'load_peak_deviation', 'load_recovery_time', 'steps', 'warnings'] and j['warnings'] == []"
check_json "settings keys" "list(j['settings']) == ['rule', 'P', 'M', 'lambda', 'formula']"
check_json "step keys" "sorted(j['steps'][0]) == sorted(['time', 'from', 'to', 'rise_time', 'overshoot_percent', 'settling_time', 'steady_state_error', 'first_move', 'settling_band', 'settled', 'ripple', 'steady_input', 'overshoot_beyond_ripple_percent'])"
# A set-point beyond the steady outputs of a Hammerstein model's map (the
# v0.1.0 staircase model reaches 0.07..193 N at duty 0..100 %): the warning on
# stderr is also in the JSON's warnings.
expect_ok "reach warning" control --model \
  "$SRC/tests/data/model_files/v0.1.0-6962d7c/stair.nonlinear.json#hammerstein" --plant ipa \
  --setpoint "staircase:levels=50 250,dwell=1" --duration 2 --json
check_output "reach warning" "pneumid control: warning: the set-point reaches [50, 250], beyond the steady outputs [0.06562, 193.2]" "$TMP/err"
check_json "reach warning" "len(j['warnings']) == 1 and j['warnings'][0].startswith('the set-point reaches [50, 250], beyond')"
expect_ok "json keys" control --controller dmc --model fopdt-paper --Ts 0.01 \
  --setpoint "staircase:levels=0 1,dwell=0.5" --duration 1 --json
check_json "no load step" "j['load_peak_deviation'] is None and j['settings']['rule'] == 'shridhar-cooper'"
# P and M without lambda override the default rule (not explicit), as in `pneumid run`.
expect_ok "override" control --model fopdt-paper --Ts 0.01 --setpoint step:from=0,to=1,at=0 \
  --duration 0.5 --P 50 --M 4 --json
check_json "override" "j['settings']['rule'] == 'shridhar-cooper' and j['settings']['P'] == 50 and j['settings']['M'] == 4"
# --input-map: the controller behind the inverse of an actuator map (here an
# S-shaped map with a dead zone up to 10 %), designed on the model at unit gain.
cat > "$TMP/map.json" <<'JSON'
{"u": [0, 10, 30, 50, 70, 90, 100], "y": [0, 0, 20, 60, 110, 140, 140]}
JSON
expect_ok "input map" control --controller mpc --model fopdt:K=1,tau=0.2,theta=0.01 \
  --plant fopdt:K=1,tau=0.2,theta=0.01 --Ts 0.01 --setpoint step:from=0,to=80,at=0.1 \
  --duration 3 --input-map "$TMP/map.json" --json
check_json "input map" "'with inverse map (7 knots' in j['controller'] and j['u_min'] >= 0 and j['u_max'] <= 100"
echo '{"u": [0, 50, 100], "y": [0, 80, 40]}' > "$TMP/bad_map.json"
expect_error "input map not monotone" "not monotone" control --model fopdt-paper --Ts 0.01 \
  --setpoint step:from=0,to=1,at=0 --duration 0.5 --input-map "$TMP/bad_map.json"
expect_error "input map missing" "cannot open static map file" control --model fopdt-paper \
  --Ts 0.01 --setpoint step:from=0,to=1,at=0 --duration 0.5 --input-map "$TMP/none.json"
echo '{"num": [1], "den": [0.2, 1]}' > "$TMP/map_none.json"
expect_error "input map absent" "holds no static map" control --model fopdt-paper --Ts 0.01 \
  --setpoint step:from=0,to=1,at=0 --duration 0.5 --input-map "$TMP/map_none.json"

# A configuration without [io] plant: the plant is the model, as without
# --plant (it was the IPA, whose 0..100 % duty a negative-gain model could
# not drive, and the output stayed at 0).
cat > "$TMP/neg.toml" <<'TOML'
[controller]
model = "fopdt:K=-2,tau=1,theta=0.1"
type = "mpc"

[loop]
period = 0.05
TOML
expect_ok "config without a plant" control --config "$TMP/neg.toml" --setpoint step:to=1,at=1 \
  --duration 10 --json
check_json "the model is the plant" "j['plant'].startswith('fopdt:K=-2') and j['settled'] and abs(j['steady_state_error']) < 0.01 and j['u_min'] < -0.4"
# NaN or a zero horizon in [controller] would stand for the rule's value: an error.
printf '[controller]\nmodel = "fopdt-paper"\ntype = "mpc"\nlambda = nan\n' > "$TMP/nan.toml"
expect_error "lambda = nan" "nan.toml:4:10: [controller] lambda must be a number, got nan" \
  control --config "$TMP/nan.toml" --setpoint step:to=1 --duration 1
printf '[controller]\nmodel = "fopdt-paper"\ntype = "dmc"\nM = 0\n' > "$TMP/m0.toml"
expect_error "M = 0" "[controller] M must be >= 1, got 0" control --config "$TMP/m0.toml" \
  --setpoint step:to=1 --duration 1
expect_error "aggressiveness nan" "--aggressiveness: must be in [0, 1], got nan" tune \
  --model fopdt-paper --Ts 0.01 --rule auto --aggressiveness nan
expect_error "overshoot nan" "--overshoot: must be >= 0, got nan" tune --model fopdt-paper \
  --Ts 0.01 --rule auto --overshoot nan
# The rule auto that cannot meet its specification says so (it ran silently).
expect_ok "auto, impossible target" control --rule auto --model fopdt-paper --Ts 0.01 \
  --response-time 0.001 --setpoint step:to=1 --duration 1 --json
check_json "auto warning" "any('the rule auto found no design' in w for w in j['warnings'])"
check_output "auto warning on stderr" "the rule auto found no design" "$TMP/err"
expect_ok "auto, met" control --rule auto --model fopdt-paper --Ts 0.01 --setpoint step:to=1 \
  --duration 1 --json
check_json "no auto warning" "j['warnings'] == []"
# --compare: auto among the rules; a pid compares its own rules.
expect_ok "compare auto" control --model fopdt-paper --Ts 0.01 --setpoint step:to=1,at=0.1 \
  --duration 2 --compare shridhar-cooper,auto --json
check_json "compare auto labels" "[r['label'] for r in j['compare']] == ['shridhar-cooper', 'auto']"
expect_ok "compare pid" control --controller pid --model fopdt-paper --Ts 0.01 \
  --setpoint step:to=1,at=0.1 --duration 2 --compare --json
check_json "compare pid rules" "[r['label'] for r in j['compare']] == ['pid simc', 'pid imc'] and j['compare'][0]['controller'] != j['compare'][1]['controller']"
expect_error "compare pid, dmc rule" "simc, imc or auto" control --controller pid \
  --model fopdt-paper --Ts 0.01 --setpoint step:to=1 --duration 1 --compare shridhar-cooper
# run on a simulated linear plant: no 0..100 clamp either.
expect_ok "run, linear plant" run --controller mpc --model fopdt:K=-2,tau=0.5,theta=0.05 \
  --plant fopdt:K=-2,tau=0.5,theta=0.05 --fast --setpoint step:to=1,at=0.5 --duration 4 --json
check_json "run reaches the set-point" "j['metrics']['settled'] and abs(j['metrics']['steady_state_error']) < 0.01"
# SIMC outside its range (a lightly damped model, zeta 0.1): the loop grows,
# and control says so; DMC on the same model settles without a word.
expect_ok "simc on zeta 0.1" control --controller pid --pid-rule simc --model "tf:num=1,den=1 0.2 1" \
  --Ts 0.05 --setpoint step:to=1,at=1 --duration 30 --json
check_json "an unstable loop is named" "any('looks unstable' in w for w in j['warnings'])"
expect_ok "dmc on zeta 0.1" control --controller dmc --model "tf:num=1,den=1 0.2 1" --Ts 0.05 \
  --setpoint step:to=1,at=1 --duration 30 --json
check_json "a settled loop has no such warning" "j['warnings'] == [] and j['settled']"
# A duration no trace holds (1e308 s ran 2 samples and exited 0).
expect_error "duration 1e308" "a simulation holds at most 1e8" control --model fopdt-paper \
  --setpoint step:to=1 --duration 1e308
finish
