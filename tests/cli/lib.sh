#!/usr/bin/env bash
# Shared helpers of the command-line tests (tests/cli/*_test.sh). Each test
# starts with
#
#   source "$(dirname "${BASH_SOURCE[0]}")/lib.sh" "$@"
#
# and is run by ctest as `bash NAME_test.sh /path/to/pneumid`. This sets
#   PNEUMID   the program (first argument; a usage message when missing)
#   PY        a Python with numpy and scipy
#   SRC       the repository root
#   TMP       a scratch directory, removed on exit
# and defines the helpers below. Failures are counted (the test goes on); on
# exit a test with failures prints their number and exits 1. A test ends
# with `finish` (its last command may be a check whose status is not the
# test's). A test may
# define `cleanup` (e.g. to stop a server); it runs on exit too. The helpers
# also work under `set -e`.
set -u

if [ $# -lt 1 ] || [ -z "$1" ]; then
  echo "usage: bash $(basename "$0") /path/to/pneumid" >&2
  exit 2
fi
PNEUMID=$1
PY=/usr/bin/python3
SRC=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
TMP=$(mktemp -d "${TMPDIR:-/tmp}/pneumid-cli-test.XXXXXX")
failures=0

_lib_exit() {
  local rc=$?
  if declare -F cleanup >/dev/null; then cleanup; fi
  rm -rf "$TMP"
  if [ "$failures" -ne 0 ]; then
    echo "$(basename "$0"): $failures failure(s)" >&2
    exit 1
  fi
  if [ "$rc" -eq 0 ]; then echo "$(basename "$0"): all checks passed"; fi
  exit "$rc"
}
trap _lib_exit EXIT

# finish: the end of a test: exit 1 when a check failed, else 0.
finish() { exit 0; }

# fail MESSAGE: counts a failure and goes on.
fail() {
  echo "FAIL: $*" >&2
  failures=$((failures + 1))
  return 0
}

# die MESSAGE: a failure after which the test cannot go on.
die() {
  fail "$@"
  exit 1
}

# expect_ok NAME ARGS...: `pneumid ARGS` exits 0; stdout in $TMP/out, stderr in $TMP/err.
expect_ok() {
  local name=$1
  shift
  local rc=0
  "$PNEUMID" "$@" >"$TMP/out" 2>"$TMP/err" || rc=$?
  [ "$rc" -eq 0 ] || fail "$name: exit $rc (expected 0): $(head -c 2000 "$TMP/err")"
  return 0
}

# expect_error NAME "stderr substring" ARGS...: `pneumid ARGS` exits non-zero
# and its stderr contains the substring.
expect_error() {
  local name=$1 pattern=$2
  shift 2
  local rc=0
  "$PNEUMID" "$@" >"$TMP/out" 2>"$TMP/err" || rc=$?
  if [ "$rc" -eq 0 ]; then
    fail "$name: exit 0 (expected an error)"
  elif ! grep -qF -- "$pattern" "$TMP/err"; then
    fail "$name: stderr lacks '$pattern': $(head -c 2000 "$TMP/err")"
  fi
  return 0
}

# check_json NAME PYTHON-EXPRESSION [FILE]: the expression, with j = the JSON
# of FILE (default: $TMP/out, the last command's stdout), is true.
check_json() {
  local name=$1 expr=$2 file=${3:-$TMP/out}
  if ! "$PY" -c "import json,sys; j=json.load(open(sys.argv[1])); sys.exit(0 if ($expr) else 1)" \
    "$file"; then
    fail "$name: '$expr' is false for $(head -c 2000 "$file")"
  fi
  return 0
}

# check_output NAME "substring" [FILE]: FILE (default: $TMP/out) contains the substring.
check_output() {
  local name=$1 pattern=$2 file=${3:-$TMP/out}
  grep -qF -- "$pattern" "$file" || fail "$name: lacks '$pattern': $(head -c 2000 "$file")"
  return 0
}

# check_png FILE: FILE exists and starts with the PNG signature.
check_png() {
  if [ ! -s "$1" ]; then
    fail "$1: no PNG written"
  elif ! head -c 8 "$1" | od -An -tx1 | grep -q "89 50 4e 47 0d 0a 1a 0a"; then
    fail "$1 is not a PNG"
  fi
  return 0
}

# check_svg FILE: FILE exists and its root element is <svg>.
check_svg() {
  if [ ! -s "$1" ]; then
    fail "$1: no SVG written"
  elif ! "$PY" -c "import sys, xml.etree.ElementTree as E; \
sys.exit(0 if E.parse(sys.argv[1]).getroot().tag.endswith('svg') else 1)" "$1"; then
    fail "$1 is not an SVG document"
  fi
  return 0
}

# check_help COMMAND FLAG...: `pneumid COMMAND --help` exits 0 and lists each flag.
check_help() {
  local command=$1
  shift
  if ! "$PNEUMID" "$command" --help >"$TMP/help" 2>&1; then
    fail "$command --help: exit non-zero"
    return 0
  fi
  local flag
  for flag in "$@"; do
    grep -qF -- "$flag" "$TMP/help" || fail "$command --help lacks $flag"
  done
  return 0
}

# data_rows FILE: the number of data rows of a CSV (no comments, no header).
data_rows() { grep -v '^#' "$1" | tail -n +2 | wc -l; }

# write_arx_prbs_data FILE SEED: 3000 samples (Ts = 0.01 s) of the paper's
# ARX(3,3,1) force model (Eq. 5) driven by a PRBS between 10 and 90 % held for
# 3 samples, with ARX noise e ~ N(0, 0.3^2) through 1/A; columns t,u,y.
write_arx_prbs_data() {
  "$PY" - "$1" "$2" <<'PYEOF'
import sys
import numpy as np
from scipy.signal import lfilter
rng = np.random.default_rng(int(sys.argv[2]))
n = 3000
u = np.repeat(np.where(rng.random(n // 3) > 0.5, 90.0, 10.0), 3)
a = [1, -0.6087, -0.2702, -0.06021]
y = lfilter([0, 0.03938, 0.04506, 0.01286], a, u) + lfilter([1], a, rng.normal(0, 0.3, n))
np.savetxt(sys.argv[1], np.c_[np.arange(n) * 0.01, u, y], delimiter=",", header="t,u,y", comments="")
PYEOF
}
