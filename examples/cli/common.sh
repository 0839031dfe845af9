# Shared start of the examples/cli scripts (sourced, not run):
#   source "$(dirname "${BASH_SOURCE[0]}")/common.sh" "$@"
# Arguments of every script: [PNEUMID] [OUTDIR]
#   PNEUMID  the pneumid program (default: $PNEUMID, else build/pneumid of
#            this repository)
#   OUTDIR   where the outputs go (created); default: a temporary directory,
#            removed at the end
# Sets PNEUMID, OUT, ROOT (the repository) and PY (a Python 3 for reading
# JSON), and defines check CONDITION MESSAGE.
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
PNEUMID=${1:-${PNEUMID:-$ROOT/build/pneumid}}
# A Python 3 for reading JSON (only its json module is used): $PYTHON, else
# Debian's /usr/bin/python3, else python3 on PATH.
if [ -n "${PYTHON:-}" ]; then PY=$PYTHON; elif [ -x /usr/bin/python3 ]; then PY=/usr/bin/python3; else PY=python3; fi
if [ ! -x "$PNEUMID" ]; then
  echo "$(basename "$0"): no pneumid program at '$PNEUMID' (give its path as the first argument)" >&2
  exit 2
fi
if [ -n "${2:-}" ]; then
  OUT=$2
  mkdir -p "$OUT"
else
  OUT=$(mktemp -d "${TMPDIR:-/tmp}/pneumid-example.XXXXXX")
  trap 'rm -rf "$OUT"' EXIT
fi

# json FILE EXPRESSION: prints the Python expression evaluated with j = the JSON of FILE.
json() { "$PY" -c 'import json, sys; j = json.load(open(sys.argv[1])); print(eval(sys.argv[2]))' "$1" "$2"; }

# check "PYTHON CONDITION" MESSAGE [FILE]: exits 1 with MESSAGE unless the
# condition (j = the JSON of FILE, when given) holds.
check() {
  local condition=$1 message=$2 file=${3:-}
  if [ -n "$file" ]; then
    "$PY" -c 'import json, sys; j = json.load(open(sys.argv[1])); sys.exit(0 if eval(sys.argv[2]) else 1)' \
      "$file" "$condition" || { echo "check failed: $message ($condition)" >&2; exit 1; }
  else
    "$PY" -c 'import sys; sys.exit(0 if eval(sys.argv[1]) else 1)' "$condition" ||
      { echo "check failed: $message ($condition)" >&2; exit 1; }
  fi
  echo "ok: $message"
}
