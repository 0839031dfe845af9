#!/usr/bin/env bash
# pneumid validate: fit and residual tests of an identified model.
# Usage: bash validate_test.sh /path/to/pneumid
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh" "$@"
set -eo pipefail
pneumid=$PNEUMID
dir=$TMP
write_arx_prbs_data "$dir/prbs.csv" 2

"$pneumid" validate --help | grep -q -- "--plot" || fail "--help lacks --plot"
"$pneumid" identify "$dir/prbs.csv" --method arx --na 3 --nb 3 --nk 1 -o "$dir/arx.json" >/dev/null
"$pneumid" identify "$dir/prbs.csv" --method arx --na 1 --nb 1 --nk 1 -o "$dir/arx1.json" >/dev/null

out="$("$pneumid" validate "$dir/arx.json" "$dir/prbs.csv" --horizon 5 --plot "$dir/v.png")"
grep -q "verdict: pass" <<<"$out" || fail "ARX(3,3,1) residuals should pass: $out"
grep -q "5-step prediction fit" <<<"$out" || fail "no k-step fit: $out"
[[ -s "$dir/v.png" ]] || fail "no plot written"

json="$("$pneumid" validate "$dir/arx1.json" "$dir/prbs.csv" --json)"
"$PY" - "$json" <<'PY' || fail "JSON of the under-modelled ARX(1,1,1)"
import json, sys
j = json.loads(sys.argv[1])
assert j["residuals"]["passed"] is False, j["residuals"]["passed"]
assert 0 < j["fit_percent"] < 100
assert len(j["residuals"]["autocorrelation"]["values"]) == 26
PY

# A transfer-function spec is validated by simulation.
"$pneumid" validate arx-paper "$dir/prbs.csv" | grep -q "simulation fit" || fail "model spec"

# Errors: clear message, non-zero exit.
if "$pneumid" validate arx-paper "$dir/prbs.csv" --horizon 3 2>"$dir/err"; then fail "horizon on a tf"; fi
grep -q "horizon" "$dir/err" || fail "horizon message: $(cat "$dir/err")"
echo '{"models": []}' >"$dir/empty.json"
if "$pneumid" validate "$dir/empty.json" "$dir/prbs.csv" 2>"$dir/err"; then fail "accepted empty models"; fi
grep -q "empty" "$dir/err" || fail "empty-models message: $(cat "$dir/err")"
expect_error "max-lag" "--max-lag: must be an integer >= 1, got 0" validate arx-paper "$dir/prbs.csv" --max-lag 0
expect_error "plot extension" "must end in .png or .svg" validate arx-paper "$dir/prbs.csv" --plot "$dir/v.eps"

# --initial-state estimate (MATLAB compare 'e'): a record cut in the middle of
# the step response is explained from the estimated state, not from rest.
"$PY" - "$SRC/tests/identify/data/fopdt.csv" "$dir/cut.csv" <<'PYEOF'
import sys
import numpy as np
d = np.loadtxt(sys.argv[1], delimiter=",", skiprows=2)
k = int(np.searchsorted(d[:, 0], 2.0))  # 1 s after the step at t = 1 s
np.savetxt(sys.argv[2], d[k:, :3], delimiter=",", header="t,u,y", comments="")
PYEOF
"$pneumid" identify "$SRC/tests/identify/data/fopdt.csv" -m fit-p1d -o "$dir/p1d.json" > /dev/null 2>&1 \
  || fail "identify fit-p1d"
expect_ok "zero state" validate "$dir/p1d.json" "$dir/cut.csv" --json --max-lag 10
zero=$("$PY" -c "import json,sys; print(json.load(open(sys.argv[1]))['fit_percent'])" "$TMP/out")
expect_ok "estimated state" validate "$dir/p1d.json" "$dir/cut.csv" --initial-state estimate --json --max-lag 10
check_json "estimate beats rest" 'j["initial_state"] == "estimate" and j["fit_percent"] > '"$zero"' + 5'
expect_error "bad initial state" "--initial-state" validate "$dir/p1d.json" "$dir/cut.csv" --initial-state e
finish
