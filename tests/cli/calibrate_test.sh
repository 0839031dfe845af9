#!/usr/bin/env bash
# CLI test of `pneumid calibrate`: data simulated from a perturbed parameter
# file give the perturbed values back, the written twin drives `simulate`, and
# bad input is refused with a message naming the problem.
# Usage: bash calibrate_test.sh /path/to/pneumid
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh" "$@"

check_help calibrate DATA --validation --plant-config --free --bound --initial-state \
  --max-iterations --threads --output --plot --json

# A perturbed actuator: bore 0.020248 -> 0.0212 m (+4.7 %), inlet and exhaust
# conductance +7.6 % and -6.25 %. Its experiments carry the simulator's
# sensor noise and ADC quantization.
cat >"$TMP/perturbed.toml" <<'TOML'
[cylinder]
bore = 0.0212
[valves]
inlet_conductance = 0.14e-8
exhaust_conductance = 0.4527e-8
TOML
"$PNEUMID" simulate --plant ipa --plant-config "$TMP/perturbed.toml" --Ts 0.01 --seed 5 \
  --input prbs:low=10,high=90,order=7,clock=0.05,at=0.5 --duration 4 -o "$TMP/prbs.csv" \
  >/dev/null || die "simulate the PRBS experiment"
"$PNEUMID" simulate --plant ipa --plant-config "$TMP/perturbed.toml" --Ts 0.01 --seed 6 \
  --input step:from=0.61,to=82,at=0.5 --duration 3 -o "$TMP/step.csv" \
  >/dev/null || die "simulate the step experiment"

# Round trip: calibrate -> twin.toml -> simulate with the twin.
expect_ok "calibrate --json" calibrate "$TMP/prbs.csv" --validation "$TMP/step.csv" \
  -o "$TMP/twin.toml" --json --plot "$TMP/fit.png"
cp "$TMP/out" "$TMP/calibrate.json"
for key in parameters experiments termination message validation correlations warnings; do
  check_json "JSON key $key" "'$key' in j" "$TMP/calibrate.json"
done
check_json "termination" "j['termination'] == 'convergence'" "$TMP/calibrate.json"
# the default twin has a sensor filter: its time constant is free by default too
check_json "default free parameters" "sorted(j['parameters']) == sorted(['cylinder.bore', \
'valves.inlet_conductance', 'valves.exhaust_conductance', 'valves.inlet_critical_ratio', \
'valves.exhaust_critical_ratio', 'valves.open_delay', 'sensors.pressure_filter_time_constant'])" \
  "$TMP/calibrate.json"
check_json "filter within 5 %" "abs(j['parameters']['sensors.pressure_filter_time_constant']\
['value'] / 0.21564 - 1) < 0.05" "$TMP/calibrate.json"
check_json "bore within 5 %" \
  "abs(j['parameters']['cylinder.bore']['value'] / 0.0212 - 1) < 0.05" "$TMP/calibrate.json"
check_json "conductances within 5 %" \
  "abs(j['parameters']['valves.inlet_conductance']['value'] / 0.14e-8 - 1) < 0.05 and \
abs(j['parameters']['valves.exhaust_conductance']['value'] / 0.4527e-8 - 1) < 0.05" \
  "$TMP/calibrate.json"
check_json "parameter fields" "all({'value', 'std', 'unit', 'determined'} <= set(p) \
for p in j['parameters'].values()) and j['parameters']['cylinder.bore']['unit'] == 'm'" \
  "$TMP/calibrate.json"
check_json "experiment fit" "j['experiments'][0]['file'].endswith('prbs.csv') and \
j['experiments'][0]['fit_percent'] >= 99 and j['experiments'][0]['initial_fit_percent'] < 99" \
  "$TMP/calibrate.json"
check_json "validation fit" "j['validation'][0]['file'].endswith('step.csv') and \
j['validation'][0]['fit_percent'] >= 99" "$TMP/calibrate.json"
check_json "output named" "j['output'].endswith('twin.toml')" "$TMP/calibrate.json"
check_png "$TMP/fit.png"
[ -s "$TMP/twin.toml" ] || fail "no twin.toml written"
grep -q "^# IPA parameters calibrated by \`pneumid calibrate\`" "$TMP/twin.toml" \
  || fail "twin.toml lacks its provenance comment"

expect_ok "simulate with the twin" simulate --plant "ipa:config=$TMP/twin.toml" \
  --input step:from=0.61,to=82,at=0.5 --duration 1 --Ts 0.01 -o "$TMP/twin_step.csv"
# The simulator names the twin's bore in mm: near 21.2, away from the built-in 20.248.
grep -o "bore [0-9.]* mm" "$TMP/out" | awk '{ exit !($2 > 20.9 && $2 < 21.5) }' \
  || fail "simulate does not use the twin's bore: $(head -1 "$TMP/out")"
[ "$(data_rows "$TMP/twin_step.csv")" -eq 101 ] || fail "twin simulation: expected 101 rows"
expect_ok "twin as --plant-config" simulate --plant ipa --plant-config "$TMP/twin.toml" \
  --duration 0.5 -o "$TMP/twin2.csv"
# The twin calibrates again from itself (start = the written file) without moving.
expect_ok "calibrate from the twin" calibrate "$TMP/prbs.csv" --plant-config "$TMP/twin.toml" \
  --free bore --json
check_json "restart stays" "abs(j['parameters']['cylinder.bore']['value'] / \
j['parameters']['cylinder.bore']['start'] - 1) < 1e-3"

# Text report: experiments, parameters, the twin's file.
expect_ok "calibrate text" calibrate "$TMP/prbs.csv" --free bore,inlet_conductance
check_output "text: termination" "IPA calibration (force mode, switching PWM): convergence"
check_output "text: parameter" "cylinder.bore"
check_output "text: experiment" "prbs.csv"

# Bad input: non-zero exit, a message on stderr naming the problem.
expect_error "unknown parameter" "unknown IPA parameter 'nosuch'" \
  calibrate "$TMP/prbs.csv" --free bore,nosuch
expect_error "bounds exclude the start" \
  "the start value of 'cylinder.bore', 0.020266 m, is outside its bounds 0.03 .. 0.04" \
  calibrate "$TMP/prbs.csv" --free bore --bound bore=0.03:0.04
expect_error "empty bounds" "lower < upper" \
  calibrate "$TMP/prbs.csv" --free bore --bound bore=0.03:0.02
expect_error "malformed bound" "expected NAME=LOWER:UPPER" \
  calibrate "$TMP/prbs.csv" --free bore --bound bore
expect_error "bound of a fixed parameter" "'valves.open_delay', which is not a free parameter" \
  calibrate "$TMP/prbs.csv" --free bore --bound open_delay=0:0.01
expect_error "non-calibratable name" \
  "'simulation.relative_tolerance' is a numerical or sensor-scaling setting" \
  calibrate "$TMP/prbs.csv" --free simulation.relative_tolerance
expect_error "parameter named twice" "named twice" \
  calibrate "$TMP/prbs.csv" --free bore,cylinder.bore

# No excitation: the input never changes.
awk -F, 'BEGIN { OFS = "," } /^#/ || /^t/ { print; next } { $2 = 50; print }' \
  "$TMP/prbs.csv" >"$TMP/constant.csv"
expect_error "constant input" "constant.csv: no excitation: the input is constant (50 %)" \
  calibrate "$TMP/constant.csv"
# A NaN in the output column: refused when the file is read, naming file and line.
awk -F, 'BEGIN { OFS = "," } /^#/ || /^t/ { print; next } ++k == 57 { $3 = "nan" } { print }' \
  "$TMP/prbs.csv" >"$TMP/nan.csv"
grep -q ",nan," "$TMP/nan.csv" || die "no NaN written"
expect_error "NaN in the data" "NaN value" calibrate "$TMP/nan.csv"
check_output "NaN: file named" "nan.csv:" "$TMP/err"
expect_error "NaN in validation data" "NaN value" \
  calibrate "$TMP/prbs.csv" --free bore --validation "$TMP/nan.csv"
# Output constant: nothing to fit.
awk -F, 'BEGIN { OFS = "," } /^#/ || /^t/ { print; next } { $3 = 1; print }' \
  "$TMP/prbs.csv" >"$TMP/flat_y.csv"
expect_error "constant output" "the output is constant" calibrate "$TMP/flat_y.csv"
expect_error "missing file" "missing.csv" calibrate "$TMP/missing.csv"
expect_error "bad initial state" "--initial-state" \
  calibrate "$TMP/prbs.csv" --initial-state warm
# No twin is written when the calibration is refused.
expect_error "no twin on error" "unknown IPA parameter" \
  calibrate "$TMP/prbs.csv" --free nosuch -o "$TMP/refused.toml"
[ ! -e "$TMP/refused.toml" ] || fail "a twin was written for a refused calibration"

finish
