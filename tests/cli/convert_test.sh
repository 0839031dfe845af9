#!/usr/bin/env bash
# CLI test of `pneumid convert`: d2c of the paper's ARX force model gives
# Eq. 6 (docs/paper.md, reference value 3) through --json; c2d/d2c round trip;
# bad input gives a non-zero exit and a message on stderr.
# Usage: bash convert_test.sh /path/to/pneumid
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh" "$@"
dir=$TMP

ARX=(--num 0,0.03938,0.04506,0.01286 --den 1,-0.60870,-0.27020,-0.06021 --Ts 0.01)

# Eq. 6: num [6.10237, -91.9458, 520011.9], den [1, 280.9917, 74994.63, 325421.7].
expect_ok "d2c json" convert "${ARX[@]}" --to continuous --method zoh --json
check_json "d2c keys" "list(j.keys()) == ['num', 'den', 'Ts', 'delay']"
check_json "d2c Ts" "j['Ts'] == 0 and j['delay'] == 0"
check_json "d2c num" "all(abs(a / b - 1) < 2e-6 for a, b in zip(j['num'], [6.10237, -91.9458, 520011.9])) and len(j['num']) == 3"
check_json "d2c den" "all(abs(a / b - 1) < 2e-6 for a, b in zip(j['den'], [1, 280.9917, 74994.63, 325421.7])) and len(j['den']) == 4"

# Human output: the transfer function, poles and DC gain.
expect_ok "d2c text" convert "${ARX[@]}" --to continuous --method zoh
grep -qF -- "-4.41102, -138.29 +/- 233.774j" "$dir/out" || fail "d2c text: poles missing: $(cat "$dir/out")"
grep -qF "DC gain: 1.59796" "$dir/out" || fail "d2c text: DC gain missing"

# The built-in spec gives the same; back to discrete returns the ARX model.
expect_ok "roundtrip" convert --model arx-paper-ct --to discrete --Ts 0.01 --method zoh --json
check_json "roundtrip" "all(abs(a - b) < 1e-9 for a, b in zip(j['den'], [1, -0.60870, -0.27020, -0.06021])) and all(abs(a - b) < 1e-9 for a, b in zip(j['num'], [0, 0.03938, 0.04506, 0.01286]))"

# FOPDT with a 0.023 s delay at Ts = 0.01: 2 whole samples, the rest by the modified z-transform.
expect_ok "fopdt c2d" convert --model fopdt:K=1.6,tau=0.245,theta=0.023 --to discrete --Ts 0.01 --json
check_json "fopdt delay" "abs(j['delay'] - 0.02) < 1e-12 and abs(sum(j['num']) / sum(j['den']) - 1.6) < 1e-9"

# --delay on --num/--den, tustin with prewarp, discrete delay carried to continuous.
expect_ok "tustin prewarp" convert --num 4 --den 1,0.8,4 --to discrete --Ts 0.1 --method tustin --prewarp 2 --json
check_json "tustin prewarp" "len(j['den']) == 3 and j['den'][0] == 1"
expect_ok "delay" convert --num 0,0.5 --den 1,-0.5 --Ts 0.1 --delay 0.3 --to continuous --json
check_json "delay" "abs(j['delay'] - 0.3) < 1e-12"

expect_ok "help" convert --help
grep -qF -- "--method" "$dir/out" || fail "help lacks --method"

# Bad input.
expect_error "pole on negative axis" "negative real axis" convert --num 0,1 --den 1,0.5 --Ts 0.1 --to continuous
expect_error "bad number" "--den: value 2 is not a finite number: 'x'" convert --num 1 --den 1,x --Ts 0.1 --to continuous
expect_error "no model" "give a model" convert --to continuous --Ts 0.1
expect_error "bad method" "unknown discretization method 'magic'" convert --num 1 --den 1,1 --to discrete --Ts 0.1 --method magic
expect_error "missing Ts" "--Ts" convert --num 1 --den 1,1 --to continuous
expect_error "bad to" "--to" convert --num 1 --den 1,1 --to sideways
expect_error "d2c foh" "use zoh or tustin" convert "${ARX[@]}" --to continuous --method foh
expect_error "unknown spec" "unknown model spec" convert --model nosuch --to discrete --Ts 0.1
expect_error "both" "not both" convert --model arx-paper --num 1 --den 1,1 --to continuous
expect_error "negative Ts" "--Ts: must be >= 0, got -0.1" convert --num 1 --den 1,1 --to discrete --Ts=-0.1

# -m is the short name of --method (as in identify and report).
expect_ok "-m" convert --num 1 --den 1,1 --to discrete --Ts 0.1 -m tustin --json
check_json "-m tustin" "abs(j['num'][0] - 0.1 / 2.1) < 1e-12"
check_help convert "-m,--method,--methods" --Ts
finish
