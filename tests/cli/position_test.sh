#!/usr/bin/env bash
# The position twin from the command line (docs/position.md): a signed
# command moves the piston both ways; a PD on the integrating model, modulated
# across the valves' dead band, positions it in `control`, in `run` and as
# generated C; set-points outside the stroke and a PID without gains on an
# integrating model are refused. Usage: bash position_test.sh PNEUMID
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh" "$@"

MODEL="tf:num=0.004,den=1 0"
# One PWM period per sample (1/300 s, the new duty latched at the next period).
PD=(--controller pid --Kc 6000 --Td 0.04 --input-gaps plant --Ts 0.0033333333333333335)

# Open loop: +20 % moves the piston out, -20 % back in; below the 9 % dead
# band nothing moves.
expect_ok "simulate" simulate --plant ipa-position --duration 2 -o "$TMP/open.csv" \
  --input "staircase:levels=0 20 0 -20 0 5 0,dwell=0.25"
$PY - "$TMP/open.csv" <<'PYEND' || fail "open-loop position: $(head -c 400 "$TMP/open.csv")"
import sys
import numpy as np
rows = [l.strip().split(",") for l in open(sys.argv[1]) if not l.startswith("#")]
head = rows[0]
d = np.array(rows[1:], dtype=float)
x, t = d[:, head.index("x [m]")], d[:, 0]  # the true position (y adds the sensor noise)
at = lambda s: x[np.argmin(abs(t - s))]
assert abs(at(0.24) - at(0.0)) < 1e-9, (at(0.0), at(0.24))  # at rest, balanced
assert at(0.74) - at(0.24) > 0.005, (at(0.24), at(0.74))   # out
assert at(1.24) - at(0.74) < -0.005, (at(0.74), at(1.24))  # back in
# 5 % is in the dead band: the piston only goes on creeping as it did at 0 %
# (the smoothed sign of the Stribeck map), about 0.2 mm/s.
creep0, creep5 = at(1.49) - at(1.24), at(1.74) - at(1.49)
assert abs(creep5) <= abs(creep0) + 1e-5, (creep0, creep5)
PYEND

# Closed loop, the issue's staircase: overshoot <= 2 %, settled within 1 s,
# |steady-state error| <= 0.1 mm at every level (docs/position.md).
expect_ok "control PD" control --model "$MODEL" --plant ipa-position "${PD[@]}" --json \
  --setpoint "staircase:levels=0.02 0.07 0.04 0.085 0.03,dwell=2.5" --duration 12.5
$PY - "$TMP/out" <<'PYEND' || fail "control PD on the position twin: $(head -c 2000 "$TMP/out")"
import json, sys
steps = json.load(open(sys.argv[1]))["steps"]
assert len(steps) == 4, steps
for s in steps:
    assert s["overshoot_percent"] <= 2.0, s
    assert s["settled"] and s["settling_time"] <= 1.0, s
    assert abs(s["steady_state_error"]) <= 1e-4, s
PYEND

# Without the modulation the command is lost in the dead band: the piston
# stops millimetres short.
expect_ok "control PD no gaps" control --model "$MODEL" --plant ipa-position --controller pid \
  --Kc 3000 --Td 0.02 --input-gaps none --json \
  --setpoint "staircase:levels=0.02 0.07,dwell=2.5" --duration 5
$PY -c 'import json,sys; s=json.load(open(sys.argv[1]))["steps"][0]; assert abs(s["steady_state_error"]) > 1e-3, s' \
  "$TMP/out" || fail "dead band without modulation: $(head -c 800 "$TMP/out")"

# In (simulated) real time, with the plant's input range -100..100 % and gaps.
expect_ok "run" run --model "$MODEL" --plant ipa-position "${PD[@]}" --fast --json \
  --setpoint "staircase:levels=0.02 0.07,dwell=2" --duration 4
$PY - "$TMP/out" <<'PYEND' || fail "run on the position twin: $(head -c 2000 "$TMP/out")"
import json, sys
j = json.load(open(sys.argv[1]))
assert j["termination"] == "success", j["termination"]
assert "-100:-91" in j["controller"], j["controller"]
s = j["metrics"]["steps"][0]
assert s["overshoot_percent"] <= 2.0 and abs(s["steady_state_error"]) <= 1e-4, s
PYEND

# Commissioning: pulses measure the velocity gain, a PD with velocity
# feed-forward is designed and verified; its controller.toml, run by
# `control --config` on a staircase and a sinusoid of other levels, meets
# docs/position.md's targets (2 %, 1 s, 0.1 mm; RMS 1 mm).
expect_ok "commission" commission --plant ipa-position -o "$TMP/commission" --json
$PY - "$TMP/out" <<'PYEND' || fail "commission on the position twin: $(head -c 2000 "$TMP/out")"
import json, sys
j = json.load(open(sys.argv[1]))
assert j["termination"] == "success", j["message"]
assert j["experiment"]["duration"] <= 10.0, j["experiment"]["duration"]
assert 0.003 < j["experiment"]["probe"]["gain"] < 0.005, j["experiment"]["probe"]  # m/s per %
assert j["controller"]["settings"]["Kff"] > 0, j["controller"]
PYEND
expect_ok "control --config (commissioned)" control --config "$TMP/commission/controller.toml" \
  --json --setpoint "staircase:levels=0.06 0.015 0.045 0.095 0.075 0.025,dwell=1.5" --duration 9
$PY - "$TMP/out" <<'PYEND' || fail "commissioned PD: $(head -c 2000 "$TMP/out")"
import json, sys
steps = [s for s in json.load(open(sys.argv[1]))["steps"] if s["time"] > 0]
assert len(steps) == 5, steps
for s in steps:
    assert s["overshoot_percent"] <= 2.0 and s["settling_time"] <= 1.0, s
    assert abs(s["steady_state_error"]) <= 1e-4, s
PYEND
expect_ok "control --config sinusoid" control --config "$TMP/commission/controller.toml" \
  --setpoint "sine:from=0.03,to=0.07,frequency=0.5" --duration 6 -o "$TMP/sine.csv"
$PY - "$TMP/sine.csv" <<'PYEND' || fail "commissioned PD on the sinusoid"
import sys
import numpy as np
d = np.genfromtxt(sys.argv[1], delimiter=",", names=True)
keep = d["t"] >= 2.0
rms = float(np.sqrt(np.mean((d["y"][keep] - d["r"][keep]) ** 2)))
assert rms <= 1e-3, rms
PYEND

# Calibration of the position twin: the mass, Coulomb and static friction of
# a heavier, stickier twin recovered from one experiment and checked on
# another of other levels.
cat > "$TMP/heavy.toml" <<'TOML'
[simulation]
mode = "position"
[mechanics]
coulomb_friction = 9.0
static_friction = 13.5
mass = 2.0
TOML
TS=0.0033333333333333335
expect_ok "simulate heavy" simulate --plant "ipa-position:config=$TMP/heavy.toml" --Ts $TS \
  --duration 4 --input "staircase:levels=0 25 0 -25 0 15 0 -35 0 20 0 -20,dwell=0.3" -o "$TMP/est.csv"
expect_ok "simulate heavy (other levels)" simulate --plant "ipa-position:config=$TMP/heavy.toml" \
  --Ts $TS --duration 3 --seed 7 -o "$TMP/val.csv" \
  --input "staircase:levels=0 -30 0 40 0 -12 0 18 0 -22,dwell=0.3"
expect_ok "calibrate position" calibrate "$TMP/est.csv" --validation "$TMP/val.csv" --mode position \
  --free mass,coulomb_friction,static_friction --output-col y --json
$PY - "$TMP/out" <<'PYEND' || fail "calibrate position: $(head -c 1500 "$TMP/out")"
import json, sys
d = json.load(open(sys.argv[1]))
p = {k: v["value"] for k, v in d["parameters"].items()}
assert abs(p["mechanics.mass"] - 2.0) < 0.02, p
assert abs(p["mechanics.coulomb_friction"] - 9.0) < 0.1, p
assert abs(p["mechanics.static_friction"] - 13.5) < 0.3, p
assert d["validation"][0]["fit_percent"] > 99.0, d["validation"]
PYEND

# Generated C of the same loop (with its sigma-delta layer).
expect_ok "codegen" codegen --model "$MODEL" --plant ipa-position "${PD[@]}" -o "$TMP/c"
grep -q "sigma-delta" "$TMP/out" || fail "codegen: no sigma-delta layer: $(cat "$TMP/out")"
[ -s "$TMP/c/pneumid_ctrl.c" ] || fail "codegen wrote no C"

# Bad input.
expect_error "set-point beyond the stroke" "outside the plant's position range 0 .. 0.1 m" \
  control --model "$MODEL" --plant ipa-position "${PD[@]}" \
  --setpoint "step:from=0.05,to=0.12,at=1" --duration 2
expect_error "run: set-point beyond the stroke" "set-point -0.01 m at t = 0 s" \
  run --model "$MODEL" --plant ipa-position "${PD[@]}" --fast \
  --setpoint "step:from=-0.01,to=0.05,at=1" --duration 2
expect_error "PID without gains on an integrator" "give the gains" \
  control --model "$MODEL" --plant ipa-position --controller pid \
  --setpoint "step:from=0.05,to=0.06,at=1" --duration 2
finish
