#!/usr/bin/env bash
# Generated controllers on a Cortex-M4F: `pneumid codegen` writes the paper's
# DMC (P = 126, M = 5), the constrained MPC and a PID with the model as a
# linear plant; examples/cortex-m4 cross-compiles each with Debian's
# gcc-arm-none-eabi (newlib, hardware float), runs it under qemu-system-arm
# (mps2-an386, semihosting, -icount, a timeout) and on the host, and
# compare.py checks that the traces agree within float tolerance.
# Exit 77 (skipped) when the cross tools or QEMU are missing.
# Usage: bash cortex_m4_test.sh PNEUMID
source "$(dirname "${BASH_SOURCE[0]}")/../cli/lib.sh" "$@"

for tool in arm-none-eabi-gcc arm-none-eabi-size qemu-system-arm make gcc; do
  if ! command -v "$tool" >/dev/null; then
    echo "cortex_m4_test.sh: $tool not found (scripts/setup installs it); skipped"
    trap - EXIT
    rm -rf "$TMP"
    exit 77
  fi
done

common=(--model fopdt-paper --Ts 0.01 --u-min 0 --u-max 100 --prefix ctrl --with-plant plant)
run_case() {
  local name=$1 precision=$2
  shift 2
  expect_ok "$name codegen" codegen "${common[@]}" --precision "$precision" -o "$TMP/$name" \
    --cpu-mhz "${CPU_MHZ:-168}" --json "$@"
  cp "$TMP/out" "$TMP/$name.codegen.json"
  if ! make -s -C "$SRC/examples/cortex-m4" GEN="$TMP/$name" TIMEOUT=60 run \
    COMPARE_FLAGS=--json >"$TMP/$name.json" 2>"$TMP/$name.err"; then
    fail "$name: target run or comparison failed: $(head -c 2000 "$TMP/$name.err")"
    return 0
  fi
  check_json "$name report" "j['steps'] == 2000 and j['precision'] == '$precision' \
and j['max_relative_difference_u'] <= j['tolerance'] and j['instructions_per_step_mean'] > 0 \
and j['ctrl_text'] > 0 and j['state_bytes'] > 0 and j['stack_all_static'] \
and 0 < j['stack_bytes_bound'] < 1024" "$TMP/$name.json"
  # The real-time certificate bounds the measured worst step.
  "$PY" - "$TMP/$name.json" "$TMP/$name.codegen.json" "$name" <<'PY' || fail "$name: a step exceeds the certificate"
import json, sys
run, gen = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
bound = gen["certificate"]["max_instructions_per_step"]
worst = run["instructions_per_step_max"]
print(f"{sys.argv[3]}: worst step {worst:.0f} instructions, certificate {bound:.0f} "
      f"({worst / bound:.2f}), QP cap {gen['certificate']['qp_max_iterations']}")
sys.exit(0 if worst <= bound else 1)
PY
  echo "$name: $(tr -d '\n ' <"$TMP/$name.json")"
}

run_case dmc float --controller dmc --P 126 --M 5 --lambda 2.25
run_case mpc_constrained float --controller mpc --P 126 --M 5 --lambda 2.25 --du-max 4 --y-max 82
run_case qdmc float --controller dmc --constrained --P 126 --M 5 --lambda 2.25 --du-max 4 --y-max 82
run_case mpc_auto float --controller mpc --rule auto
run_case gpc float --controller gpc --P 126 --M 5 --lambda 2.25
run_case pid_double double --controller pid
# A slow clock (30 MHz): the certificate caps the QP at one iteration, which the
# set-point changes reach (the fallback applies the clipped unconstrained move).
CPU_MHZ=30 run_case mpc_capped float --controller mpc --P 126 --M 5 --lambda 2.25 --du-max 4 --y-max 82
echo '{"u": [0, 10, 30, 60, 85, 90, 100], "y": [0, 2, 40, 95, 135, 193, 200]}' >"$TMP/map.json"
run_case mpc_input_map float --controller mpc --input-map "$TMP/map.json" --du-max 4

# The STM32F4 board example (timer interrupt, ADC, PWM) links with a
# generated module; no board is needed to build it.
expect_ok "board codegen" codegen --model fopdt-paper --Ts 0.01 --plant ipa --controller mpc \
  --rule auto --precision float --prefix ctrl --y-valid-min -5 --y-valid-max 300 -o "$TMP/board"
if make -s -C "$SRC/examples/stm32f4" GEN="$TMP/board" >"$TMP/board.txt" 2>&1; then
  echo "stm32f4 board: $(tail -1 "$TMP/board.txt")"
else
  fail "stm32f4 board example does not build: $(head -c 2000 "$TMP/board.txt")"
fi
# The paper's DMC: the state is yhat_0..yhat_N, f_1..f_P and two scalars (float).
check_json "dmc state" "j['state_bytes'] % 4 == 0 and j['state_bytes'] > 4 * (126 + 2)" "$TMP/dmc.json"
finish
