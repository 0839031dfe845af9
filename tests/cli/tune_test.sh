#!/usr/bin/env bash
# pneumid tune: the paper's conventional settings (docs/paper.md, reference value 6),
# the modified settings, and error handling. Usage: bash tune_test.sh PNEUMID
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh" "$@"

out=$("$PNEUMID" tune --model fopdt:K=1.6,tau=0.245,theta=0.001 --Ts 0.01 --rule shridhar-cooper --M 5 --json) \
  || fail "tune shridhar-cooper exited non-zero"
echo "$out" | $PY -c '
import json, sys
j = json.load(sys.stdin)
assert j["P"] == 126, j["P"]
assert j["M"] == 5, j["M"]
assert abs(j["lambda"] - 2.2508) < 1e-3, j["lambda"]
assert abs(j["lambda_formula"] - 2.24) < 1e-9, j["lambda_formula"]
assert j["rule"] == "shridhar-cooper"
assert "lambda_max" in j["formula"], j["formula"]
' || fail "shridhar-cooper JSON: $out"

out=$("$PNEUMID" tune --model fopdt-paper --Ts 0.01 --rule paper-modified --json) || fail "paper-modified"
echo "$out" | $PY -c '
import json, sys
j = json.load(sys.stdin)
assert (j["P"], j["M"], j["lambda"]) == (126, 10, 1.92), j
assert "not published" in j["formula"]
' || fail "paper-modified JSON: $out"

# Text output names the formula.
"$PNEUMID" tune --model fopdt-paper --Ts 0.01 | grep -q "lambda_max(A'A)/500" || fail "text output"
"$PNEUMID" tune --help | grep -q -- "--rule" || fail "--help"

# Errors: non-zero exit and a message on stderr.
err=$("$PNEUMID" tune --model fopdt-paper --Ts 0.01 --rule nonsense 2>&1 >/dev/null) && fail "bad rule accepted"
echo "$err" | grep -q "shridhar-cooper" || fail "bad rule message: $err"
expect_error "negative Ts" "--Ts: must be > 0, got -1" tune --model fopdt-paper --Ts -1
"$PNEUMID" tune --model fopdt-paper --Ts 0.01 --rule explicit >/dev/null 2>&1 && fail "explicit without P accepted"
# --sample-time is an alias of --Ts.
expect_ok "sample-time alias" tune --model fopdt-paper --sample-time 0.01 --json
check_json "sample-time alias" "j['P'] == 126"

# --rule auto: MPC settings for a specification, predicted metrics on the
# model, robustness rows and a design review (control/auto_tuning.hpp).
expect_ok "auto mpc" tune --rule auto --controller mpc --model fopdt-paper --Ts 0.01 --json
check_json "auto mpc keys" "all(k in j for k in ('rule', 'controller', 'P', 'M', 'lambda', 'predicted', 'robustness', 'review', 'termination', 'message'))"
check_json "auto mpc settings" "j['rule'] == 'auto' and j['controller'] == 'mpc' and j['P'] == 126 and j['M'] == 5 and j['lambda'] > 0"
# Without --response-time: the fastest design that passes the robustness rows.
check_json "auto mpc spec met" "j['termination'] == 'converged' and j['predicted']['overshoot_percent'] <= 5.05 and j['specification']['response_time_source'] == 'fastest robust' and abs(j['predicted']['rise_time'] / j['specification']['response_time'] - 1) <= 0.2 and j['predicted']['rise_time'] < 0.246"
check_json "auto mpc robustness" "len(j['robustness']) == 3 and all(r['pass'] for r in j['robustness'])"
check_json "auto mpc review" "{r['check'] for r in j['review']} >= {'nominal stability', 'offset-free', 'QP Hessian condition', 'constraint conflicts', 'specification'} and all(r['status'] != 'fail' for r in j['review'])"
# With a response time: the design aims at it.
expect_ok "auto mpc target" tune --rule auto --controller mpc --model fopdt-paper --Ts 0.01 --response-time 0.246 --json
check_json "auto mpc target met" "j['termination'] == 'converged' and j['predicted']['overshoot_percent'] <= 5.05 and abs(j['predicted']['rise_time'] / 0.246 - 1) <= 0.2 and j['specification']['response_time_source'] == 'given or model'"
expect_ok "auto pid" tune --rule auto --controller pid --model fopdt-paper --Ts 0.01 --aggressiveness 0.2 --json
# The SIMC PI (Ti = tau = 0.245 s) settles sooner than the loop shaped to a
# 69 deg phase margin and replaces it; the review names both.
check_json "auto pid gains" "j['Kc'] > 0 and abs(j['Ti'] - 0.245) < 1e-9 and j['Td'] == 0 and j['P'] is None and j['predicted']['overshoot_percent'] < 0.5"
check_json "auto pid review" "any(r['check'] == 'loop shaping' and 'SIMC PI' in r['message'] and 'phase margin 69 deg' in r['message'] for r in j['review'])"
expect_ok "auto text" tune --rule auto --controller dmc --model fopdt-paper --Ts 0.01
check_output "auto text review" "review:"
check_output "auto text termination" "termination: converged"
# The MPC's Kalman noises are part of the design: the sensor's variance
# (0.003 N^2) gives a faster estimator and so another lambda than the default
# 1, and tune evaluates what control --rule auto deploys with the same flags.
expect_ok "auto noise" tune --rule auto --model fopdt-paper --Ts 0.01 --measurement-noise 0.003 --json
check_json "auto noise lambda" "abs(j['lambda'] - 0.734941) < 1e-5"
"$PNEUMID" control --controller mpc --rule auto --model fopdt-paper --Ts 0.01 --measurement-noise 0.003 \
  --setpoint step:from=0,to=10,at=0.1 --duration 1 --json | $PY -c 'import json, sys; j = json.load(sys.stdin); s = j["settings"]; assert abs(s["lambda"] - 0.734941) < 1e-5, s' \
  || fail "control deploys another lambda than tune evaluated"
expect_error "noise without auto" "apply to --rule auto only" tune --model fopdt-paper --Ts 0.01 --measurement-noise 1
# A spec that cannot be met is a review that says why, not a crash.
expect_ok "auto impossible" tune --rule auto --model fopdt-paper --Ts 0.01 --response-time 0.001 --u-min 0 --u-max 100 --json
check_json "auto impossible" "j['termination'] == 'spec_not_met' and any(r['check'] == 'specification' and r['status'] == 'fail' and 'input held at its limit' in r['message'] for r in j['review'])"
expect_error "auto gpc" "not gpc" tune --rule auto --controller gpc --model fopdt-paper --Ts 0.01
expect_error "auto knob" "--aggressiveness: must be in [0, 1], got 2" tune --rule auto --model fopdt-paper --Ts 0.01 --aggressiveness 2
expect_error "auto flags without auto" "apply to --rule auto only" tune --model fopdt-paper --Ts 0.01 --overshoot 3
# --plant: the plant's input range bounds the design, as in `control --plant`,
# so both print the same settings (on the IPA: duty 0..100 %).
expect_ok "auto with plant" tune --rule auto --model fopdt-paper --Ts 0.01 --plant ipa --json
cp "$TMP/out" "$TMP/tune_plant.json"
expect_ok "auto without plant" tune --rule auto --model fopdt-paper --Ts 0.01 --json
cp "$TMP/out" "$TMP/tune_free.json"
expect_ok "auto with limits" tune --rule auto --model fopdt-paper --Ts 0.01 --u-min 0 --u-max 100 --json
check_json "plant range = explicit limits" "j['lambda'] == json.load(open('$TMP/tune_plant.json'))['lambda']"
check_json "plant range bounds the design" "j['lambda'] != json.load(open('$TMP/tune_free.json'))['lambda']"
expect_ok "control auto on the plant" control --controller mpc --rule auto --model fopdt-paper --plant ipa --Ts 0.01 --setpoint step:from=0,to=40,at=0.1 --duration 0.5 --json
check_json "tune --plant = control --plant" "abs(j['settings']['lambda'] / json.load(open('$TMP/tune_plant.json'))['lambda'] - 1) < 1e-9 and j['settings']['P'] == json.load(open('$TMP/tune_plant.json'))['P']"
expect_error "plant without auto" "apply to --rule auto only" tune --model fopdt-paper --Ts 0.01 --plant ipa
expect_error "unknown plant" "nosuch" tune --rule auto --model fopdt-paper --Ts 0.01 --plant nosuch
expect_error "limits outside the plant" "--u-min 50 is above --u-max" tune --rule auto --model fopdt-paper --Ts 0.01 --plant ipa --u-min 50 --u-max 20
finish
