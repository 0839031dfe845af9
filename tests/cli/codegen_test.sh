#!/usr/bin/env bash
# pneumid codegen: the C module of each controller is written, compiles under
# gcc -std=c99 -Wall -Wextra -Werror -pedantic, and runs; --json sizes, the
# --max-ram budget and unsupported options give clear errors.
# Usage: bash codegen_test.sh PNEUMID
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh" "$@"

check_help codegen --controller --precision --prefix --max-ram --output --json --P --M --lambda

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

# Bad input.
expect_error "ram budget" "above the budget of 1000 bytes" codegen "${common[@]}" --controller dmc \
  --max-ram 1000 -o "$TMP/x"
echo '{"u": [0, 10, 100], "y": [0, 0, 150]}' > "$TMP/map.json"
expect_error "input map" "does not support a controller behind an input map" codegen "${common[@]}" \
  --controller mpc --input-map "$TMP/map.json" -o "$TMP/x"
expect_error "precision" "precision" codegen "${common[@]}" --controller dmc --precision half -o "$TMP/x"
expect_error "prefix" "not a C identifier" codegen "${common[@]}" --controller dmc --prefix "a-b" -o "$TMP/x"
expect_error "controller" "controller" codegen "${common[@]}" --controller lqr -o "$TMP/x"
expect_error "gpc constrained" "--constrained selects QDMC" codegen "${common[@]}" --controller gpc \
  --constrained -o "$TMP/x"
expect_error "pid y bound" "not of pid" codegen "${common[@]}" --controller pid --y-max 80 -o "$TMP/x"
expect_error "no output" "--output" codegen "${common[@]}" --controller dmc
[ ! -e "$TMP/x" ] || fail "a failed run wrote $TMP/x"
finish
