#!/usr/bin/env bash
# CLI test of `pneumid step`: stepinfo metrics against MATLAB's documented
# example and first-order closed forms; bad input gives an error on stderr.
# Usage: bash step_test.sh /path/to/pneumid
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh" "$@"
dir=$TMP

# MATLAB documentation: H = tf([8 18 32],[1 6 14 24]); stepinfo(H):
# RiseTime 0.2087, SettlingTime 3.4972, Overshoot 26.5302, Peak 1.6871, PeakTime 0.5987.
expect_ok "matlab example" step --num 8,18,32 --den 1,6,14,24 --json
check_json "keys" "all(k in j for k in ['rise_time', 'settling_time', 'overshoot', 'undershoot', 'peak', 'peak_time', 'steady_state'])"
check_json "rise" "abs(j['rise_time'] - 0.2087) < 1e-3"
check_json "settling" "abs(j['settling_time'] - 3.4972) < 2e-3"
check_json "overshoot" "abs(j['overshoot'] - 26.5302) < 0.05"
check_json "peak" "abs(j['peak'] / 1.6871 - 1) < 1e-3 and abs(j['peak_time'] - 0.5987) < 0.02"
check_json "steady" "abs(j['steady_state'] - 32 / 24) < 1e-12"

# FOPDT: rise time tau ln 9, settling time theta + tau ln 50, no overshoot.
expect_ok "fopdt" step --model fopdt-paper --json
check_json "fopdt rise" "abs(j['rise_time'] - 0.245 * 2.1972245773) < 0.245 / 200"
check_json "fopdt settling" "abs(j['settling_time'] - (0.001 + 0.245 * 3.9120230054)) < 0.245 / 200"
check_json "fopdt overshoot" "j['overshoot'] == 0 and abs(j['steady_state'] - 1.6) < 1e-12"

# The paper's models, text output.
expect_ok "arx-paper-ct" step --model arx-paper-ct
grep -q "rise_time" "$dir/out" || fail "arx-paper-ct: no rise_time line"
expect_ok "arx-paper" step --model arx-paper --t-final 2 --json
check_json "arx steady" "abs(j['steady_state'] - 1.59796) < 1e-5"
expect_ok "help" step --help
grep -qF -- "--t-final" "$dir/out" || fail "help lacks --t-final"

# Unstable: metrics are null in JSON, exit 0.
# An unstable model has no step metrics: a clear error, and the response is
# still drawn over a finite horizon when asked for.
expect_error "unstable" "the model is not stable (pole 1 with real part >= 0)" \
  step --num 1 --den 1,-1 --json
expect_error "unstable plot" "the response up to 2 s is plotted" \
  step --num 1 --den 1,-1 --t-final 2 --plot "$dir/unstable.png"
[ -s "$dir/unstable.png" ] || fail "unstable plot: no file written"
expect_error "unstable discrete" "|z| = 1.5 >= 1" step --model tf:num=1,den=1,-1.5,Ts=0.1

# Commas inside a spec continue the coefficient list: den = [1, 1].
expect_ok "comma list" step --model tf:num=1,den=1,1 --json
check_json "comma list" "abs(j['steady_state'] - 1) < 1e-9"

# A discrete model of order 199 with poles near the unit circle: the automatic
# horizon is bounded (this ran for hours); a continuous one that cannot be
# simulated in double precision is an error, not NaN metrics.
den200=$($PY -c "print(','.join(['1'] + ['0'] * 198 + ['-0.999']))")
if ! timeout 60 "$PNEUMID" step --model "tf:num=1,den=$den200,Ts=0.01" --json >"$dir/out" 2>"$dir/err"; then
  grep -qF "error" "$dir/err" || fail "order 199 discrete: no result and no error in 60 s"
fi
# (s + 1)^n: order 20 needs more than 7 time constants to settle (metrics were
# NaN); order 150 cannot be handled from its coefficients: a clear error.
binomial() { $PY -c "from math import comb; print(' '.join(str(comb($1, k)) for k in range($1 + 1)))"; }
expect_ok "order 20" step --model "tf:num=1,den=$(binomial 20)" --json
check_json "order 20" "j['settling_time'] is not None and 25 < j['settling_time'] < 40"
expect_error "ill-conditioned" "the roots of a polynomial of order 150 are ill-conditioned" \
  step --model "tf:num=1,den=$(binomial 150)"

# Model files: a number beyond double and a directory name the file.
echo '{"num": [72e377], "den": [1, 1]}' >"$dir/huge.json"
expect_error "huge number" "huge.json: invalid model JSON: number overflow" step --model "$dir/huge.json"
expect_error "directory" "$dir: is a directory, not a model file" step --model "$dir"

expect_error "no model" "give a model" step
expect_error "bad den" "--den: value 1 is not a finite number" step --num 1 --den abc
expect_error "improper" "improper" step --num 1,2,3 --den 1,1
expect_error "bad threshold" "settling_threshold" step --model fopdt-paper --settling-threshold 2
expect_error "bad tfinal" "--t-final: must be >= 0, got -1" step --model fopdt-paper --t-final -1
expect_error "bad dt" "--dt: must be >= 0, got -0.1" step --model fopdt-paper --dt=-0.1

# --plot: a PNG or an SVG of the response; other extensions are refused when parsing.
expect_ok "plot png" step --model fopdt-paper --plot "$dir/step.png"
check_png "$dir/step.png"
check_output "plot png" "plot written to $dir/step.png"
expect_ok "plot svg json" step --num 8,18,32 --den 1,6,14,24 --plot "$dir/step.svg" --json
check_svg "$dir/step.svg"
check_json "plot json" "j['plot'] == '$dir/step.svg' and abs(j['peak'] / 1.6871 - 1) < 1e-3"
check_output "svg title" "Step response of G(s)" "$dir/step.svg"
expect_error "plot extension" "must end in .png or .svg" step --model fopdt-paper --plot "$dir/step.pdf"
[ -e "$dir/step.pdf" ] && fail "plot extension: a file was written"
expect_error "bad spec" "key 'tau': not a finite number" step --model fopdt:K=1,tau=zz
finish
