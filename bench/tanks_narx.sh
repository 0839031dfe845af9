#!/usr/bin/env bash
# Cascaded-tanks benchmark (data/tanks) with polynomial NARX models: each
# option set is identified on estimation.csv (structure chosen on that record
# only: its last 30 %, or the split given) and scored by the RMSE of its free
# run on validation.csv, with the time of the identification.
#   bash bench/tanks_narx.sh [PNEUMID_BINARY]   (default build/pneumid)
# Published: linear BLA 0.757 V, PNLSS 0.45 V, grey box 0.19 V.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
B=${1:-$root/build/pneumid}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
printf '%-48s %10s %8s  %s\n' "options" "RMSE [V]" "time [s]" "structure"
while IFS= read -r opts; do
  start=$(date +%s.%N)
  # shellcheck disable=SC2086
  "$B" identify "$root/data/tanks/estimation.csv" -m narx $opts -o "$dir/m.json" >/dev/null 2>&1
  end=$(date +%s.%N)
  rmse=$("$B" validate "$dir/m.json#narx" "$root/data/tanks/validation.csv" --json |
    python3 -c 'import json, sys; r = json.load(sys.stdin)["rmse"]; print("diverges" if r is None else f"{r:.3f}")')
  structure=$(python3 -c 'import json, sys; m = json.load(open(sys.argv[1]))["models"][0]; p = m["params"]; print("ny = nu = %d, nk = %d, %d terms, %s" % (p["ny"], p["nk"], p["terms"], m["termination"]))' "$dir/m.json")
  printf '%-48s %10s %8.1f  %s\n' "$opts" "$rmse" "$(echo "$end - $start" | bc)" "$structure"
done <<'LIST'
--degree 1
--degree 2
--degree 3
--degree 1 --focus simulation
--degree 2 --focus simulation
--degree 3 --focus simulation
--degree 3 --focus simulation --split 0.8
--degree 3 --focus simulation --split 0.6
LIST
