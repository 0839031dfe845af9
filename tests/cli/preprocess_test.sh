#!/usr/bin/env bash
# Preprocessing flags of identify, validate, orders and report: offsets and
# trends, window, filter, decimation; the model file records them and validate
# re-applies them; clear errors for windows outside the data, decimation below
# 1, filters above Nyquist.
# Usage: bash preprocess_test.sh /path/to/pneumid   (cwd: a scratch/build directory)
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh" "$@"

for cmd in identify validate orders report; do
  check_help "$cmd" --window --resample --remove-initial --detrend --filter --decimate
done

# The paper's ARX model on PRBS data, then the same record with an offset of
# 50 on the input and 300 on the output and a drift of 2/s on the output (a
# real plant's operating point): ARX(3,3,1) on the raw record is poor, on the
# detrended one it finds the model again.
write_arx_prbs_data "$TMP/clean.csv" 11
"$PY" - "$TMP/clean.csv" "$TMP/offset.csv" <<'PYEOF'
import sys
import numpy as np
d = np.loadtxt(sys.argv[1], delimiter=",", skiprows=1)
d[:, 1] += 50.0
d[:, 2] += 300.0 + 2.0 * d[:, 0]
np.savetxt(sys.argv[2], d, delimiter=",", header="t,u,y", comments="")
PYEOF
expect_ok "clean" identify "$TMP/clean.csv" -m arx --json
clean=$("$PY" -c "import json,sys; print(json.load(open(sys.argv[1]))['models'][0]['params']['a'][1])" "$TMP/out")
expect_ok "raw offsets" identify "$TMP/offset.csv" -m arx --operating-point zero --json
check_json "raw is off" 'abs(j["models"][0]["params"]["a"][1] - ('"$clean"')) > 0.5 and j["models"][0]["fit_percent"] < 0'
# By default the offsets become the model's operating point (the means); the
# drift still needs --detrend linear.
expect_ok "default operating point" identify "$TMP/offset.csv" -m arx --json
check_json "operating point stored" 'abs(j["models"][0]["operating_point"]["u0"] - 98.4) < 5 and j["models"][0]["operating_point"]["y0"] > 300'
expect_error "bad operating point" "operating point" identify "$TMP/offset.csv" -m arx --operating-point median
# The one-step predictor and the residual tests of validate act on the
# deviations from that operating point too (started from raw levels they
# would see the offsets as errors).
expect_ok "default to file" identify "$TMP/offset.csv" -m arx -o "$TMP/op.json"
expect_ok "one-step prediction" validate "$TMP/op.json#arx" "$TMP/offset.csv" --horizon 1 --json
check_json "prediction around the operating point" 'j["prediction"]["fit_percent"] > 88'  # 76.5 % from raw levels

expect_ok "detrended" identify "$TMP/offset.csv" -m arx --detrend linear --json
check_json "detrended recovers" 'abs(j["models"][0]["params"]["a"][1] - ('"$clean"')) < 0.05 and j["models"][0]["fit_percent"] > 60'
check_json "recorded" 'j["models"][0]["preprocessing"]["offsets"] == "linear"'

# The record travels with the model: validate re-applies the estimation
# data's trend (not re-estimated) and gives the fit identify printed.
expect_ok "to file" identify "$TMP/offset.csv" -m arx --detrend linear -o "$TMP/m.json"
fit=$("$PY" -c "import json,sys; print('%.2f' % json.load(open(sys.argv[1]))['models'][0]['fit_percent'])" "$TMP/m.json")
expect_ok "validate re-applies" validate "$TMP/m.json" "$TMP/offset.csv"
check_output "same fit" "simulation fit: $fit %"
expect_error "double offsets" "carries the preprocessing" validate "$TMP/m.json" "$TMP/offset.csv" --detrend constant
expect_ok "window with a recorded model" validate "$TMP/m.json" "$TMP/offset.csv" --window 5:25

# Window, decimation, filter: the sample count and time base follow.
expect_ok "window" identify "$TMP/clean.csv" -m arx --window 5:15 --json
check_json "window samples" 'j["estimation_samples"] == 1001'
expect_ok "decimate" identify "$TMP/clean.csv" -m arx --decimate 3 --json
check_json "decimated Ts" 'abs(j["models"][0]["discrete"]["Ts"] - 0.03) < 1e-12 and j["estimation_samples"] == 1000'
expect_ok "orders" orders "$TMP/offset.csv" --detrend linear --na-range 3 --nb-range 3 --nk-range 1 --json
expect_ok "report" report "$TMP/offset.csv" -m arx --detrend linear -o "$TMP/rep"
grep -q "detrend" "$TMP/rep/report.html" || fail "report lacks the preprocessing row"
grep -q -- "--detrend linear" "$TMP/rep/report.html" || fail "report's command lacks --detrend"

# Errors name the flag, the data and the offending values.
expect_error "window outside" "window 50:60 s lies outside the data" identify "$TMP/clean.csv" -m arx --window 50:60
expect_error "window order" "window '9:5'" identify "$TMP/clean.csv" -m arx --window 9:5
expect_error "decimate 0" "--decimate must be an integer factor >= 1, got 0" identify "$TMP/clean.csv" -m arx --decimate 0
expect_error "above Nyquist" "above the Nyquist frequency 50 Hz" identify "$TMP/clean.csv" -m arx --filter lowpass:60
expect_error "bad filter" "--filter: filter 'highpass:3'" identify "$TMP/clean.csv" -m arx --filter highpass:3
expect_error "two offset removals" "--remove-initial and --detrend" identify "$TMP/clean.csv" -m arx --remove-initial --detrend constant
finish
