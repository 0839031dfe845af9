#!/usr/bin/env bash
# CLI test of `pneumid step`: stepinfo metrics against MATLAB's documented
# example and first-order closed forms; bad input gives an error on stderr.
# Usage: bash step_test.sh /path/to/pneumid
set -u
PNEUMID=${1:?usage: step_test.sh /path/to/pneumid}
PY=/usr/bin/python3
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
failures=0

fail() { echo "FAIL: $*" >&2; failures=$((failures + 1)); }

expect_ok() {
  local name=$1; shift
  if ! "$PNEUMID" "$@" >"$dir/out" 2>"$dir/err"; then
    fail "$name: exit non-zero (expected 0): $(cat "$dir/err")"
  fi
}

expect_error() {
  local name=$1 pattern=$2; shift 2
  "$PNEUMID" "$@" >"$dir/out" 2>"$dir/err"
  local rc=$?
  if [ "$rc" -eq 0 ]; then
    fail "$name: exit 0 (expected an error)"
  elif ! grep -qF -- "$pattern" "$dir/err"; then
    fail "$name: stderr lacks '$pattern': $(cat "$dir/err")"
  fi
}

check_json() {
  local name=$1 expr=$2
  if ! $PY -c "import json,sys; j=json.load(open('$dir/out')); sys.exit(0 if ($expr) else 1)"; then
    fail "$name: '$expr' is false for $(cat "$dir/out")"
  fi
}

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
expect_ok "unstable" step --num 1 --den 1,-1 --json
check_json "unstable" "j['rise_time'] is None"

expect_error "no model" "give a model" step
expect_error "bad den" "--den: coefficient 1 is not a finite number" step --num 1 --den abc
expect_error "improper" "improper" step --num 1,2,3 --den 1,1
expect_error "bad threshold" "settling_threshold" step --model fopdt-paper --settling-threshold 2
expect_error "bad tfinal" "t_final must be >= 0" step --model fopdt-paper --t-final -1
expect_error "bad spec" "field 'tau': not a finite number" step --model fopdt:K=1,tau=zz

if [ "$failures" -ne 0 ]; then
  echo "$failures failure(s)" >&2
  exit 1
fi
echo "step: all checks passed"
