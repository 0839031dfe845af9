#!/usr/bin/env bash
# MPC design on the built-in IPA simulator: step test -> model -> tuning to
# specifications -> closed-loop simulation on the nonlinear simulator, with a
# load step, against the paper's DMC as the baseline.
#
# The IPA (intelligent pneumatic actuator): input PWM duty in %, output
# force in N, Ts = 0.01 s (docs/simulator.md).
#
# Usage: bash examples/cli/mpc_design.sh [PNEUMID] [OUTDIR]
# Writes OUTDIR/step.csv, models.json, tune.json, mpc.json, mpc.csv, mpc.png, dmc.json.
source "$(dirname "${BASH_SOURCE[0]}")/common.sh" "$@"
SETPOINT="staircase:levels=0 40 80 40,dwell=2"

# 1. An open-loop step test of the simulator, 0.61 -> 82 % duty at 1 s.
"$PNEUMID" simulate --plant ipa --input step:from=0.61,to=82,at=1.0 --duration 4 --Ts 0.01 \
  --seed 1 -o "$OUT/step.csv"

# 2. Models of it; fit-p1d is a first order plus dead time fitted to the record.
"$PNEUMID" identify "$OUT/step.csv" -m fit-p1d,arx,oe -o "$OUT/models.json"

# 3. The fastest robust MPC design for the model: P, M and lambda from a
#    closed-loop search, with the duty limits of the plant (--plant ipa).
"$PNEUMID" tune --rule auto --model "$OUT/models.json#fit-p1d" --Ts 0.01 --plant ipa
"$PNEUMID" tune --rule auto --model "$OUT/models.json#fit-p1d" --Ts 0.01 --plant ipa \
  --json > "$OUT/tune.json"
check "j['termination'] == 'converged'" "the design meets its specification" "$OUT/tune.json"

# 4. The same MPC in closed loop with the nonlinear simulator: 0/40/80/40 N,
#    2 s per level, a -15 N load at 7 s. -o writes the trace, --plot a figure.
"$PNEUMID" control --controller mpc --rule auto --model "$OUT/models.json#fit-p1d" --plant ipa \
  --Ts 0.01 --setpoint "$SETPOINT" --duration 8 --load-step at=7,size=-15 \
  -o "$OUT/mpc.csv" --plot "$OUT/mpc.png" --json > "$OUT/mpc.json"

# 5. The paper's DMC (FOPDT of the paper, Shridhar-Cooper tuning) on the same run.
"$PNEUMID" control --controller dmc --rule shridhar-cooper --model fopdt-paper --plant ipa \
  --Ts 0.01 --setpoint "$SETPOINT" --duration 8 --load-step at=7,size=-15 --json > "$OUT/dmc.json"

iae_mpc=$(json "$OUT/mpc.json" "j['iae']")
iae_dmc=$(json "$OUT/dmc.json" "j['iae']")
echo "IAE: MPC $(json "$OUT/mpc.json" "round(j['iae'], 2)") N s," \
  "paper's DMC $(json "$OUT/dmc.json" "round(j['iae'], 2)") N s"
echo "MPC overshoot per step: $(json "$OUT/mpc.json" "[round(s['overshoot_percent'], 2) for s in j['steps']]") %"

# Today: IAE 9.41 (MPC) against 13.36 N s (DMC); overshoot 0.51 / 5.64 / 7.98 %.
check "$iae_mpc < 11 and $iae_mpc < $iae_dmc" "the MPC tracks with less IAE than the paper's DMC"
check "all(s['overshoot_percent'] < 12 for s in j['steps'])" "overshoot below 12 % on every step" "$OUT/mpc.json"
check "j['u_min'] >= 0 and j['u_max'] <= 100" "duty within 0..100 %" "$OUT/mpc.json"
check "j['load_recovery_time'] is not None and j['load_recovery_time'] < 0.5" \
  "the -15 N load is rejected within 0.5 s" "$OUT/mpc.json"
if [ -n "${2:-}" ]; then echo "outputs in $OUT"; fi
echo "mpc_design: all checks passed"
