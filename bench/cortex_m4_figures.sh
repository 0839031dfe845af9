#!/usr/bin/env bash
# The table "Figures on the Cortex-M4F" of docs/codegen.md: each controller
# generated in float and double (fopdt-paper, Ts = 0.01 s, P = 126, M = 5,
# lambda = 2.25, 0..100 % (the unconstrained MPC without limits), for QDMC
# and MPC du <= 4 and y <= 82 soft; the float rows certified at 168 MHz, the
# double ones, which cannot be, with the default cap) and run 2000 steps under QEMU with
# examples/cortex-m4 (needs gcc-arm-none-eabi, libnewlib-arm-none-eabi and
# qemu-system-arm); one markdown row each.
#   bash bench/cortex_m4_figures.sh [PNEUMID_BINARY]   (default build/pneumid)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
B=${1:-$root/build/pneumid}
PY=${PY:-/usr/bin/python3}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
common=(--model fopdt-paper --Ts 0.01 --prefix ctrl --with-plant plant --json)
row() {  # label precision codegen-args...
  local label=$1 precision=$2
  shift 2
  local gen="$dir/gen"
  rm -rf "$gen"
  local clock=()
  [ "$precision" = float ] && clock=(--cpu-mhz 168)
  "$B" codegen "${common[@]}" "${clock[@]}" --precision "$precision" -o "$gen" "$@" \
    >"$dir/codegen.json"
  make -s -C "$root/examples/cortex-m4" GEN="$gen" TIMEOUT=600 PYTHON="$PY" run \
    COMPARE_FLAGS=--json >"$dir/run.json"
  "$PY" - "$label" "$precision" "$dir/codegen.json" "$dir/run.json" <<'PY'
import json, sys
label, precision = sys.argv[1], sys.argv[2]
gen, run = json.load(open(sys.argv[3])), json.load(open(sys.argv[4]))
cert = gen["certificate"]
cap = cert.get("qp_max_iterations")
bound = cert["max_instructions_per_step"]
certificate = f"{bound:.0f}" if bound < 1e7 else f"{bound:.3g}"
print(f"| {label} | {precision} | {run['ctrl_text']} | {gen['const_bytes']} | "
      f"{run['state_bytes']} | {run['instructions_per_step_mean']:.0f} | "
      f"{run['instructions_per_step_max']:.0f} | {certificate} | {cap if cap else '-'} |",
      flush=True)
PY
}
echo "| controller | precision | flash: text (B) | of which tables (B) | RAM: state (B) | instructions / step, mean | largest | certificate (instructions) | QP cap |"
echo "|---|---|---|---|---|---|---|---|---|"
tuning=(--P 126 --M 5 --lambda 2.25)
limits=(--u-min 0 --u-max 100)
bounds=(--du-max 4 --y-max 82)
for precision in float double; do
  row "DMC (paper, N = 508)" "$precision" --controller dmc "${tuning[@]}" "${limits[@]}"
  row "QDMC" "$precision" --controller dmc --constrained "${tuning[@]}" "${limits[@]}" \
    "${bounds[@]}"
  row "MPC, unconstrained" "$precision" --controller mpc "${tuning[@]}"
  row "MPC, constrained" "$precision" --controller mpc "${tuning[@]}" "${limits[@]}" \
    "${bounds[@]}"
  row "GPC" "$precision" --controller gpc "${tuning[@]}" "${limits[@]}"
  row "PID" "$precision" --controller pid "${limits[@]}"
done
