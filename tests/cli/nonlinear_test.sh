#!/usr/bin/env bash
# pneumid identify -m static-map|hammerstein|wiener|hw|narx on the IPA twin: one
# 60 s experiment (staircase 0..100 % in 5 % steps for 30 s, then a
# multi-level PRBS for 30 s), validated on another experiment; the model file
# keeps the maps and NARX terms and `validate` simulates them.
# Usage: bash nonlinear_test.sh /path/to/pneumid
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh" "$@"
set -eo pipefail
dir=$TMP

# The input: the staircase before t_switch, the PRBS after (file signal).
experiment() {  # stair-spec prbs-spec t_switch duration out.csv
  "$PNEUMID" simulate --plant fopdt:K=1,tau=1,theta=0 --input "$1" --duration "$4" \
    -o "$dir/s1.csv" >/dev/null
  "$PNEUMID" simulate --plant fopdt:K=1,tau=1,theta=0 --input "$2" --duration "$4" \
    -o "$dir/s2.csv" >/dev/null
  paste -d, <(grep -v '^#' "$dir/s1.csv" | cut -d, -f1,2) <(grep -v '^#' "$dir/s2.csv" | cut -d, -f2) |
    awk -F, -v sw="$3" 'NR == 1 {print "t,u"; next} {print $1 "," (($1 < sw - 1e-9) ? $2 : $3)}' \
      >"$dir/in.csv"
  "$PNEUMID" simulate --plant ipa --input "file:$dir/in.csv" --duration "$4" --Ts 0.01 \
    -o "$5" >/dev/null
}
experiment "staircase:levels=0 5 10 15 20 25 30 35 40 45 50 55 60 65 70 75 80 85 90 95 100,dwell=1.4" \
  "prbs-levels:low=10,high=90,levels=5,clock=0.3,seed=1,at=30" 30 60 "$dir/est.csv"
experiment "staircase:levels=0 25 55 85 45 15 65 95 35 5,dwell=2" \
  "prbs-levels:low=5,high=95,levels=7,clock=0.4,seed=7,at=20" 20 50 "$dir/val.csv"

help="$("$PNEUMID" identify --help)"
grep -q "hammerstein" <<<"$help" || fail "--help lacks the nonlinear methods"
"$PNEUMID" identify "$dir/est.csv" -m arx,oe,fit-p1d,hammerstein,wiener,hw,narx,affine-narx --na 2 --nb 2 \
  --nk 1 --nf 2 --knots 21 --max-terms 15 --validation "$dir/val.csv" -o "$dir/models.json" \
  >"$dir/table.txt"
grep -q "input map f(u): .*21 knots" "$dir/table.txt" || fail "no map knots printed: $(cat "$dir/table.txt")"
grep -q "selected terms: " "$dir/table.txt" || fail "no NARX terms printed"
"$PY" - "$dir/models.json" <<'PY' || fail "validation fits"
import json, math, sys
models = {m["method"]: m for m in json.load(open(sys.argv[1]))["models"]}
# a model whose simulation diverges on the held-out data has no validation fit
fit = {k: m.get("validation_fit_percent", -math.inf) for k, m in models.items()}
print(" ".join(f"{k}={v:.1f}" for k, v in sorted(fit.items())))
linear = max(fit["arx"], fit["oe"], fit["fit-p1d"])
nonlinear = max(fit["hammerstein"], fit["wiener"], fit["narx"], fit["affine-narx"])
assert linear <= 80.0, fit
assert nonlinear >= 90.0 and nonlinear - linear >= 12.0, fit
assert fit["affine-narx"] >= 90.0, fit  # fills faster than it vents: only it reaches 90 %
assert math.isfinite(fit["hw"]) and fit["hw"] > linear, fit
hw = models["hw"]
assert len(hw["input_map"]["u"]) == 21 and len(hw["output_map"]["u"]) == 21, hw
assert len(models["hammerstein"]["input_map"]["u"]) == 21
assert "output_map" in models["wiener"] and "narx" in models["narx"]
assert "narx" in models["affine-narx"] and len(models["affine-narx"]["input_map"]["u"]) == 21
PY

# validate simulates the affine NARX (map, then NARX) and the
# Hammerstein-Wiener model (input map, G, output map) as identify scored them;
# a controller refuses a NARX model with a clear message.
for method in affine-narx hw; do
  out="$("$PNEUMID" validate "$dir/models.json#$method" "$dir/val.csv" --initial-state estimate --json)"
  "$PY" - "$out" "$dir/models.json" "$method" <<'PY' || fail "validate of $method"
import json, sys
v = json.loads(sys.argv[1])
m = {m["method"]: m for m in json.load(open(sys.argv[2]))["models"]}[sys.argv[3]]
assert abs(v["fit_percent"] - m["validation_fit_percent"]) < 1e-6, (v["fit_percent"], m)
PY
done
expect_error "NARX model as a plant" "is a NARX model, which has no transfer function" \
  simulate --plant "$dir/models.json#affine-narx" --input step:from=0,to=40 --duration 1

# The MPC behind the affine NARX's input-output linearization holds across the
# force range: staircase 10 -> 40 -> 80 -> 120 -> 60 -> 20 N on the twin,
# overshoot <= 5 % and settling <= 0.7 s after every step (measured: overshoot
# 0.2-0.4 %, settling 0.48-0.63 s in the 0.8 N band behind the twin's 0.22 s
# measurement lag).
"$PNEUMID" control --controller mpc --rule auto --model "$dir/models.json#affine-narx" --plant ipa \
  --Ts 0.01 --setpoint "staircase:levels=10 40 80 120 60 20,dwell=2" --duration 12 --json \
  >"$dir/narx_loop.json" || fail "control with the affine NARX model"
"$PY" - "$dir/narx_loop.json" <<'PY' || fail "closed loop with the affine NARX model"
import json, sys
j = json.load(open(sys.argv[1]))
assert "behind a NARX linearization" in j["controller"], j["controller"]
steps = j["steps"]
assert [(s["from"], s["to"]) for s in steps] == [(10, 40), (40, 80), (80, 120), (120, 60), (60, 20)], steps
for s in steps:
    assert s["overshoot_percent"] <= 5.0 and s["settled"] and s["settling_time"] <= 0.7, s
assert 0.0 <= j["u_min"] and j["u_max"] <= 100.0, j
PY
# The report draws nonlinear models as they are (maps and NARX, not their
# linear parts) and their static maps as a figure of their own.
"$PNEUMID" report "$dir/est.csv" --methods arx,hammerstein,affine-narx -o "$dir/rep" >/dev/null ||
  fail "report with nonlinear models"
"$PY" - "$dir/rep" <<'PY' || fail "report of nonlinear models"
import json, re, sys
html = open(sys.argv[1] + "/report.html").read()
models = {m["method"]: m for m in json.load(open(sys.argv[1] + "/models.json"))["models"]}
assert "Static input maps" in html
for method in ("hammerstein", "affine-narx"):
    drawn = re.findall(re.escape(method) + r" \([^)]*\) \(fit ([0-9.]+) %\)", html)
    assert drawn and abs(float(drawn[0]) - models[method]["fit_percent"]) < 0.06, (method, drawn)
PY
expect_error "--input-map beside a NARX model" "brings its own input map" \
  control --controller mpc --model "$dir/models.json#affine-narx" --input-map "$dir/models.json#hammerstein" \
  --plant ipa --setpoint step:from=0,to=40 --duration 1
expect_error "NARX model as --input-map" "is not the plant's static map" \
  control --controller mpc --model fopdt-paper --input-map "$dir/models.json#affine-narx" \
  --plant ipa --setpoint step:from=0,to=40 --duration 1

# validate reads the maps back and simulates them as identify scored them
# (identify scores held-out data from the estimated initial state).
out="$("$PNEUMID" validate "$dir/models.json#hammerstein" "$dir/val.csv" --initial-state estimate --json)"
"$PY" - "$out" "$dir/models.json" <<'PY' || fail "validate of the Hammerstein model"
import json, sys
v = json.loads(sys.argv[1])
m = {m["method"]: m for m in json.load(open(sys.argv[2]))["models"]}["hammerstein"]
assert abs(v["fit_percent"] - m["validation_fit_percent"]) < 1e-6, (v["fit_percent"], m)
PY

# --monotone-map keeps the Hammerstein input map invertible.
"$PNEUMID" identify "$dir/est.csv" -m hammerstein --monotone-map --na 3 --nb 3 --nk 1 --knots 21 \
  --json >"$dir/mono.json"
"$PY" - "$dir/mono.json" <<'PY' || fail "monotone Hammerstein map"
import json, sys
f = json.load(open(sys.argv[1]))["models"][0]["input_map"]
assert all(b >= a for a, b in zip(f["y"], f["y"][1:])), f["y"]
PY

# The static map from the staircase part.
"$PNEUMID" identify "$dir/est.csv" -m static-map --min-segment 1.2 --json >"$dir/map.json"
"$PY" - "$dir/map.json" <<'PY' || fail "static map"
import json, sys
m = json.load(open(sys.argv[1]))["models"][0]
f = m["input_map"]
assert len(f["u"]) == 21 and f["u"][0] == 0 and f["u"][-1] == 100, f["u"]
assert all(b >= a for a, b in zip(f["y"], f["y"][1:])), f["y"]  # monotone
assert abs(f["y"][-1] - 193.2) < 1.0, f["y"][-1]  # saturation at the supply pressure
PY

# Errors: a constant input never leaves one operating point; 0.3 s of data
# are fewer samples than the NARX candidates.
"$PNEUMID" simulate --plant ipa --input "step:from=40,to=40" --duration 3 -o "$dir/flat.csv" >/dev/null
expect_error "constant input" "never leaves one operating point" identify "$dir/flat.csv" -m static-map
expect_error "narx candidates" "84 candidate terms (ny = 3, nu = 3, degree = 3) exceed the" \
  identify "$dir/val.csv" --window 1.9:2.2 -m narx --na 3 --nb 3 --degree 3
finish
