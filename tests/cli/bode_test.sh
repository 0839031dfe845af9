#!/usr/bin/env bash
# CLI test of `pneumid bode`: margins of the paper's FOPDT against closed forms
# (gain crossover sqrt(1.6^2 - 1)/0.245 rad/s; phase margin and crossover from
# tests/lti/gen_frequency_cases.py), and errors for bad input.
# Usage: bash bode_test.sh /path/to/pneumid
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh" "$@"
dir=$TMP

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
check_help bode --w-min --w-max --points --plot --json

# --points alone: that many frequencies over the automatic range.
expect_ok "points alone" bode --model fopdt-paper --points 7 --json
check_json "points alone" "len(j['omega']) == 7"

# Numeric flags out of range are refused, naming flag and value.
expect_error "points 0" "--points: must be an integer >= 2, got 0" bode --model fopdt-paper --points 0
expect_error "w-min negative" "--w-min: must be > 0, got -1" bode --model fopdt-paper --w-min -1 --w-max 10
expect_error "w-max zero" "--w-max: must be > 0, got 0" bode --model fopdt-paper --w-min 1 --w-max 0

# --plot: magnitude and phase as PNG or SVG.
expect_ok "plot png" bode --model fopdt-paper --plot "$dir/bode.png"
check_png "$dir/bode.png"
check_output "plot png" "plot written to $dir/bode.png"
expect_ok "plot svg" bode --model arx-paper --plot "$dir/bode.svg" --json
check_svg "$dir/bode.svg"
check_json "plot json" "j['plot'] == '$dir/bode.svg'"
check_output "svg title" "Bode diagram of arx-paper" "$dir/bode.svg"
expect_error "plot extension" "must end in .png or .svg" bode --model fopdt-paper --plot "$dir/b.jpg"

"$PNEUMID" bode --model arx-paper --w-min 1 --w-max 1000 >"$dir/out" 2>"$dir/err" && fail "bode above Nyquist: exit 0"
grep -qF "Nyquist" "$dir/err" || fail "bode above Nyquist: $(cat "$dir/err")"
"$PNEUMID" bode --model fopdt-paper --w-min 10 --w-max 1 >"$dir/out" 2>"$dir/err" && fail "bode bad range: exit 0"
grep -qF "w-min" "$dir/err" || fail "bode bad range: $(cat "$dir/err")"
# One bound alone: the other from the automatic grid (it said "got 0 and 20").
expect_ok "bode --w-max alone" bode --model fopdt-paper --w-max 100 --json
check_json "bode --w-max alone" "abs(j['omega'][-1] - 100) < 1e-9 and j['omega'][0] < 1"
expect_ok "bode --w-min alone" bode --model arx-paper --w-min 5 --json
check_json "bode --w-min alone (discrete: up to Nyquist)" \
  "abs(j['omega'][0] - 5) < 1e-9 and abs(j['omega'][-1] - 3.141592653589793 / 0.01) < 1e-6"
finish
