#!/usr/bin/env bash
# pneumid codegen: the C module of each controller is written, compiles under
# gcc -std=c99 -Wall -Wextra -Werror -pedantic, and runs; --json sizes, the
# --max-ram budget and unsupported options give clear errors.
# Usage: bash codegen_test.sh PNEUMID
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh" "$@"

check_help codegen --controller --precision --prefix --max-ram --output --json --P --M --lambda \
  --cpu-mhz --period --qp-max-iterations --y-valid-min --y-valid-max --safe-input

common=(--model fopdt-paper --Ts 0.01)
for ctl in dmc gpc pid mpc; do
  expect_ok "$ctl" codegen "${common[@]}" --controller "$ctl" --plant ipa --prefix "c_$ctl" \
    -o "$TMP/$ctl" --json
  check_json "$ctl json" "j['controller'] == '$ctl' and j['prefix'] == 'c_$ctl' and j['ram_bytes'] > 0"
  for f in "c_$ctl.h" "c_$ctl.c" README.md; do
    [ -s "$TMP/$ctl/$f" ] || fail "$ctl: $f not written"
  done
  gcc -std=c99 -Wall -Wextra -Werror -pedantic -c "$TMP/$ctl/c_$ctl.c" -o "$TMP/$ctl/c.o" \
    || fail "$ctl: the module does not compile cleanly"
done
# The IPA's duty range bounds the input: the MPC solves a QP; without a
# plant and limits it does not, and --du-max alone makes it constrained.
check_json "mpc with the ipa's range" "j['constrained'] is True" "$TMP/out"
expect_ok "mpc free" codegen "${common[@]}" --controller mpc --prefix mpcu -o "$TMP/mpcu" --json
check_json "mpc free json" "j['constrained'] is False"
if grep -q "qp_solve" "$TMP/mpcu/mpcu.c"; then fail "the unconstrained MPC carries a QP solver"; fi
expect_ok "mpc qp" codegen "${common[@]}" --controller mpc --du-max 4 --precision float \
  --prefix mpcq -o "$TMP/mpcq" --json
check_json "mpc qp json" "j['constrained'] is True and j['precision'] == 'float'"
grep -q "mpcq_qp_solve" "$TMP/mpcq/mpcq.c" || fail "the constrained MPC has no QP solver"
grep -q "typedef float mpcq_real" "$TMP/mpcq/mpcq.h" || fail "float precision not in the header"

# The paper's DMC (P = 126, M = 5) runs: at rest it stays at rest, and a unit
# set-point step gives the library's first move of 0.672 (control_test.sh).
expect_ok "paper dmc" codegen "${common[@]}" --controller dmc --P 126 --M 5 --lambda 2.25 \
  --prefix paper -o "$TMP/paper"
check_output "paper dmc summary" "wrote $TMP/paper/paper.c"
cat > "$TMP/paper/main.c" <<'C'
#include <stdio.h>
#include "paper.h"
int main(void) {
  paper_state s;
  paper_init(&s);
  double u0 = paper_step(&s, 0.0, 0.0);
  double u1 = paper_step(&s, 1.0, 0.0);
  printf("%.9f %.9f\n", u0, u1);
  return 0;
}
C
gcc -std=c99 -I"$TMP/paper" "$TMP/paper/main.c" "$TMP/paper/paper.c" -o "$TMP/paper/run" -lm \
  || fail "paper dmc: link"
moves=$("$TMP/paper/run")
"$PY" -c "import sys; a, b = map(float, sys.argv[1:]); sys.exit(0 if a == 0 and abs(b - 0.672) < 1e-3 else 1)" \
  $moves || fail "paper dmc moves (0 at rest, then 0.672): $moves"

# What `control` runs, the module runs: the same options (and model file)
# give the same controller. control's trace (set-points and measurements) is
# replayed through the compiled module, double precision, with the actuator's
# 0..100 % clip and applied() as in the loop; inputs agree to 1e-9 of the
# largest (the CSV holds each value exactly).
cat > "$TMP/replay.c" <<'C'
#include <stdio.h>
#include "ctrl.h"
int main(void) {
  ctrl_state s;
  char line[512];
  double t, r, y, ym, u, d;
  int k = 0;
  if (!fgets(line, sizeof line, stdin)) return 1;
  while (fgets(line, sizeof line, stdin)) {
    double v, a;
    if (sscanf(line, "%lf,%lf,%lf,%lf,%lf,%lf", &t, &r, &y, &ym, &u, &d) != 6) return 1;
    if (k++ == 0) ctrl_reset(&s, 0.0, ym);
    v = ctrl_step(&s, r, ym);
    a = v < 0.0 ? 0.0 : (v > 100.0 ? 100.0 : v);
    if (a != v) ctrl_applied(&s, a);
    printf("%.17g %.17g\n", a, u);
  }
  return 0;
}
C
"$PNEUMID" simulate --plant ipa --Ts 0.01 --duration 30 --seed 4 \
  --input "staircase:levels=15 25 45 65 80 95 55 20 70 35 88 18 50,dwell=2.2" -o "$TMP/est.csv" \
  >/dev/null 2>&1 || fail "simulate the estimation staircase"
expect_ok "nonlinear models" identify "$TMP/est.csv" -m hammerstein,wiener,affine-narx --json \
  -o "$TMP/models.json"
echo '{"u": [0, 10, 100], "y": [0, 0, 150]}' > "$TMP/map.json"
replay() {
  local name=$1 expect_layers=$2
  shift 2
  local opts=("$@")
  expect_ok "$name control" control "${opts[@]}" --plant ipa --Ts 0.01 --duration 8 \
    --setpoint "staircase:levels=20 120 60 150 40,dwell=1.6" -o "$TMP/$name.csv"
  expect_ok "$name codegen" codegen "${opts[@]}" --plant ipa --Ts 0.01 --prefix ctrl \
    -o "$TMP/$name" --json
  check_json "$name layers" "j['layers'] == $expect_layers"
  gcc -std=c99 -O2 -ffp-contract=off -I"$TMP/$name" "$TMP/replay.c" "$TMP/$name/ctrl.c" \
    -o "$TMP/$name/replay" -lm || { fail "$name: replay does not build"; return; }
  "$TMP/$name/replay" <"$TMP/$name.csv" >"$TMP/$name.txt" || { fail "$name: replay failed"; return; }
  "$PY" - "$TMP/$name.txt" "$name" <<'PY' || fail "$name: the module's inputs differ from control's"
import sys
import numpy as np
a = np.loadtxt(sys.argv[1])
worst = np.max(np.abs(a[:, 0] - a[:, 1])) / max(1.0, np.max(np.abs(a[:, 1])))
print(f"{sys.argv[2]}: {len(a)} steps, max |u_module - u_control| = {worst:.3g} of max |u|")
sys.exit(0 if worst <= 1e-9 else 1)
PY
}
replay linear_mpc "[]" --model fopdt-paper --controller mpc
replay input_map_mpc "['input-map']" --model fopdt-paper --controller mpc --input-map "$TMP/map.json"
replay hammerstein_mpc "['input-map']" --model "$TMP/models.json#hammerstein" --controller mpc \
  --rule auto
replay hammerstein_dmc "['input-map']" --model "$TMP/models.json#hammerstein" --controller dmc
replay wiener_mpc "['output-map']" --model "$TMP/models.json#wiener" --controller mpc
replay narx_mpc "['narx-linearization']" --model "$TMP/models.json#affine-narx" --controller mpc
replay narx_pid "['narx-linearization']" --model "$TMP/models.json#affine-narx" --controller pid

# --with-plant writes a linear plant module: a model with a map is refused,
# not written without it.
if "$PNEUMID" codegen --model "$TMP/models.json#hammerstein" --controller mpc --Ts 0.01 \
  --with-plant plant -o "$TMP/hplant" 2> "$TMP/hplant.err"; then
  fail "--with-plant on a Hammerstein model wrote its linear part only"
fi
grep -q "has a static input map" "$TMP/hplant.err" || fail "--with-plant error: $(cat "$TMP/hplant.err")"

# --rule auto is reported as such (its settings are the tuner's explicit ones).
expect_ok "auto rule" codegen "${common[@]}" --controller mpc --plant ipa --rule auto --prefix ctrl \
  -o "$TMP/auto" --json
check_json "auto rule json" "j['settings']['rule'] == 'auto' and j['settings']['P'] > 0"

# Faults: a NaN or out-of-range measurement holds the last input; the range
# is set at generation (--y-valid-min/--y-valid-max) or with -D on the bench.
expect_ok "guarded" codegen "${common[@]}" --controller mpc --plant ipa --y-valid-min -5 \
  --y-valid-max 300 --prefix ctrl -o "$TMP/guard"
grep -q "define CTRL_Y_VALID_MAX 300.0" "$TMP/guard/ctrl.c" || fail "guard range not in the module"
cat > "$TMP/guard/main.c" <<'C'
#include <math.h>
#include <stdio.h>
#include "ctrl.h"
int main(void) {
  ctrl_state s;
  double u1, u2, u3, u4;
  ctrl_init(&s);
  u1 = ctrl_step(&s, 50.0, 0.0);
  u2 = ctrl_step(&s, 50.0, NAN);
  u3 = ctrl_step(&s, 50.0, 1000.0);
  u4 = ctrl_step(&s, 50.0, 1.0);
  printf("%d %d %d %d %d\n", u1 == u2 && u2 == u3, s.faults, s.fault, isfinite(u4) != 0,
         u4 >= 0.0 && u4 <= 100.0);
  return 0;
}
C
gcc -std=c99 -I"$TMP/guard" "$TMP/guard/main.c" "$TMP/guard/ctrl.c" -o "$TMP/guard/run" -lm \
  || fail "guard: link"
[ "$("$TMP/guard/run")" = "1 2 0 1 1" ] || fail "guard: held inputs and fault count: $("$TMP/guard/run")"
gcc -std=c99 -DCTRL_Y_VALID_MAX=0.5 -I"$TMP/guard" "$TMP/guard/main.c" "$TMP/guard/ctrl.c" \
  -o "$TMP/guard/run2" -lm || fail "guard -D: link"
[ "$("$TMP/guard/run2" | cut -d' ' -f2)" = "3" ] || fail "guard: -D did not move the range"

# The real-time certificate: the QP cap follows the clock and the period.
expect_ok "certificate" codegen "${common[@]}" --controller mpc --plant ipa --du-max 4 --y-max 82 \
  --precision float --cpu-mhz 168 --period 0.01 --prefix ctrl -o "$TMP/cert" --json
check_json "certificate json" "j['certificate']['max_cycles_per_step'] <= j['certificate']['budget_cycles'] \
and j['certificate']['qp_max_iterations'] >= 1 and j['certificate']['cpu_mhz'] == 168"
cap=$("$PY" -c "import json,sys; print(json.load(open(sys.argv[1]))['certificate']['qp_max_iterations'])" "$TMP/out")
grep -q "define CTRL_QP_MAX_ITERATIONS $cap\$" "$TMP/cert/ctrl.c" || fail "the certificate's cap $cap is not the module's"
expect_ok "slow clock" codegen "${common[@]}" --controller mpc --plant ipa --du-max 4 --y-max 82 \
  --precision float --cpu-mhz 30 --period 0.01 --prefix ctrl -o "$TMP/cert30" --json
check_json "slower clock, smaller cap" "j['certificate']['qp_max_iterations'] < $cap"

# Bad input.
expect_error "certificate not met" "real-time certificate cannot be met" codegen "${common[@]}" \
  --controller dmc --P 126 --M 5 --cpu-mhz 1 --period 0.001 -o "$TMP/x"
expect_error "guard range" "y_min <= y_max" codegen "${common[@]}" --controller pid \
  --y-valid-min 10 --y-valid-max 0 -o "$TMP/x"
expect_error "ram budget" "above the budget of 1000 bytes" codegen "${common[@]}" --controller dmc \
  --max-ram 1000 -o "$TMP/x"
expect_error "precision" "precision" codegen "${common[@]}" --controller dmc --precision half -o "$TMP/x"
expect_error "prefix" "not a C identifier" codegen "${common[@]}" --controller dmc --prefix "a-b" -o "$TMP/x"
expect_error "controller" "controller" codegen "${common[@]}" --controller lqr -o "$TMP/x"
expect_error "gpc constrained" "--constrained selects QDMC" codegen "${common[@]}" --controller gpc \
  --constrained -o "$TMP/x"
expect_error "pid y bound" "not of pid" codegen "${common[@]}" --controller pid --y-max 80 -o "$TMP/x"
expect_error "no output" "--output" codegen "${common[@]}" --controller dmc
[ ! -e "$TMP/x" ] || fail "a failed run wrote $TMP/x"
finish
