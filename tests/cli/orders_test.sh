#!/usr/bin/env bash
# pneumid orders: ARX order selection on data of the paper's ARX(3,3,1) model.
# Usage: bash orders_test.sh /path/to/pneumid
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh" "$@"
set -eo pipefail
pneumid=$PNEUMID
dir=$TMP
write_arx_prbs_data "$dir/prbs.csv" 1

"$pneumid" orders --help | grep -q -- "--na-range" || fail "--help lacks --na-range"
out="$("$pneumid" orders "$dir/prbs.csv" --na-range 1:4 --nb-range 1:4 --nk-range 0:2)"
grep -q "48 candidates" <<<"$out" || fail "expected 48 candidates: $out"
grep -qE "mdl +na = 3, nb = 3, nk = 1" <<<"$out" || fail "MDL should pick ARX(3,3,1): $out"

json="$("$pneumid" orders "$dir/prbs.csv" --na-range 1:4 --nb-range 1:4 --nk-range 0:2 --json)"
"$PY" - "$json" <<'PY' || fail "JSON output"
import json, sys
j = json.loads(sys.argv[1])
assert len(j["candidates"]) == 48, len(j["candidates"])
assert j["best"]["mdl"] == {"na": 3, "nb": 3, "nk": 1}, j["best"]
c = j["candidates"][0]
for k in ("na", "nb", "nk", "loss", "aic", "aicc", "fpe", "mdl"):
    assert k in c, k
PY

# Validation-data losses with --split.
"$pneumid" orders "$dir/prbs.csv" --na-range 3 --nb-range 3 --nk-range 1 --split 0.7 \
  | grep -q "loss on validation data" || fail "--split"

# Bad input: clear errors, non-zero exit, nothing on stdout.
if "$pneumid" orders "$dir/prbs.csv" --na-range 5:1 >"$dir/out" 2>"$dir/err"; then fail "accepted 5:1"; fi
grep -q "min 5 > max 1" "$dir/err" || fail "range error message: $(cat "$dir/err")"
[[ ! -s "$dir/out" ]] || fail "stdout not empty on error"
if "$pneumid" orders "$dir/missing.csv" 2>"$dir/err"; then fail "accepted a missing file"; fi
grep -q "missing.csv" "$dir/err" || fail "missing-file message: $(cat "$dir/err")"
expect_error "negative top" "--top: must be an integer >= 0, got -1" orders "$dir/prbs.csv" --top -1
finish
