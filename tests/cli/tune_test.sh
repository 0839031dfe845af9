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
finish
