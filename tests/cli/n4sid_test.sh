#!/usr/bin/env bash
# pneumid identify -m n4sid: --feedthrough (D term), --n4sid-weight, a long
# step record whose input is constant before the step (was NaN / A = 0).
# Usage: bash n4sid_test.sh /path/to/pneumid   (cwd: a scratch/build directory)
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh" "$@"

check_help identify --feedthrough --n4sid-weight

# x(t+1) = [1.5 -0.7; 1 0] x + [1; 0] u, y = [0.5 0.3] x + 0.5 u (+ noise):
# white input, 3000 samples; and a 200 000-sample step test (0.61 -> 82 at
# sample 10 000, then a slow PRBS) of the same plant without D.
$PY - "$TMP/d.csv" "$TMP/long.csv" <<'PYEOF' || die "data generation"
import sys
import numpy as np
from scipy.signal import dlsim
A = np.array([[1.5, -0.7], [1, 0]]); B = np.array([[1], [0]]); C = np.array([[0.5, 0.3]])
rng = np.random.default_rng(3)
u = rng.normal(0, 1, 3000)
_, y, _ = dlsim((A, B, C, np.array([[0.5]]), 0.01), u)
y = y[:, 0] + rng.normal(0, 0.01, u.size)
np.savetxt(sys.argv[1], np.c_[np.arange(u.size) * 0.01, u, y], delimiter=",",
           header="t,u,y", comments="", fmt="%.10g")
n = 200000
u = np.repeat(np.where(rng.random(n // 50) > 0.5, 80.0, 20.0), 50)
u[:10000] = 0.61
_, y, _ = dlsim((A, B, C, np.array([[0.0]]), 0.01), u)
y = y[:, 0] + rng.normal(0, 0.5, n)
np.savetxt(sys.argv[2], np.c_[np.arange(n) * 0.01, u, y], delimiter=",",
           header="t,u,y", comments="", fmt="%.8g")
PYEOF

expect_ok "feedthrough" identify "$TMP/d.csv" -m n4sid --na 2 --feedthrough --json
check_json "D estimated" 'abs(j["models"][0]["params"]["D"][0][0] - 0.5) < 0.01'
check_json "fit with D" 'j["models"][0]["fit_percent"] > 99'
expect_ok "no feedthrough" identify "$TMP/d.csv" -m n4sid --na 2 --json
check_json "D = 0 by default" 'j["models"][0]["params"]["D"][0][0] == 0'
for w in moesp n4sid cva CVA; do
  expect_ok "weight $w" identify "$TMP/d.csv" -m n4sid --na 2 --feedthrough --n4sid-weight "$w"
done
check_output "CVA named in the note" "CVA, order 2"
expect_error "bad weight" "unknown subspace weighting 'ssarx' (valid: moesp, n4sid, cva)" \
  identify "$TMP/d.csv" -m n4sid --n4sid-weight ssarx

expect_ok "long step record" identify "$TMP/long.csv" -m n4sid --na 2 --json
check_json "long record: finite, stable model with a good fit" \
  'j["models"][0]["fit_percent"] > 90 and "unstable" not in str(j["models"][0].get("flags", []))'
finish
