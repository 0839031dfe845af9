#!/usr/bin/env bash
# CLI test of `pneumid bode`: margins of the paper's FOPDT against closed forms
# (gain crossover sqrt(1.6^2 - 1)/0.245 rad/s; phase margin and crossover from
# tests/lti/gen_frequency_cases.py), and errors for bad input.
# Usage: bash bode_test.sh /path/to/pneumid
set -u
PNEUMID=${1:?usage: bode_test.sh /path/to/pneumid}
PY=/usr/bin/python3
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
failures=0
fail() { echo "FAIL: $*" >&2; failures=$((failures + 1)); }

if ! "$PNEUMID" bode --model fopdt-paper --w-min 1 --w-max 1000 --points 31 --json >"$dir/out" 2>"$dir/err"; then
  fail "bode json: $(cat "$dir/err")"
fi
$PY - "$dir/out" <<'PYEOF' || fail "bode json values: $(cat "$dir/out")"
import json, math, sys
j = json.load(open(sys.argv[1]))
assert list(j.keys()) == ["omega", "magnitude_db", "phase_deg", "margins"]
assert len(j["omega"]) == 31 and abs(j["omega"][0] - 1) < 1e-12
w = j["omega"][10]
assert abs(j["magnitude_db"][10] - 20 * math.log10(1.6 / math.hypot(0.245 * w, 1))) < 1e-9
assert abs(j["phase_deg"][10] - math.degrees(-math.atan(0.245 * w) - 0.001 * w)) < 1e-9
m = j["margins"]
assert abs(m["gain_crossover"] - math.sqrt(1.6 ** 2 - 1) / 0.245) < 1e-8
assert abs(m["phase_margin"] - 128.390096001754) < 1e-6
assert abs(m["phase_crossover"] - 1573.39048478462) < 1e-5
PYEOF

"$PNEUMID" bode --model fopdt-paper >"$dir/out" 2>"$dir/err" || fail "bode text: $(cat "$dir/err")"
grep -q "phase margin: 128.39 deg" "$dir/out" || fail "bode text: $(cat "$dir/out")"
"$PNEUMID" bode --help >"$dir/out" 2>&1 || fail "bode --help"

"$PNEUMID" bode --model arx-paper --w-min 1 --w-max 1000 >"$dir/out" 2>"$dir/err" && fail "bode above Nyquist: exit 0"
grep -qF "Nyquist" "$dir/err" || fail "bode above Nyquist: $(cat "$dir/err")"
"$PNEUMID" bode --model fopdt-paper --w-min 10 --w-max 1 >"$dir/out" 2>"$dir/err" && fail "bode bad range: exit 0"
grep -qF "w-min" "$dir/err" || fail "bode bad range: $(cat "$dir/err")"

if [ "$failures" -ne 0 ]; then
  echo "$failures failure(s)" >&2
  exit 1
fi
echo "bode: all checks passed"
