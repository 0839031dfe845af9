#!/usr/bin/env bash
# CLI test of `pneumid simulate` (run by ctest as: bash simulate_test.sh /path/to/pneumid).
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh" "$@"
set -eo pipefail

# --help documents the signal syntax and the plants.
"$PNEUMID" simulate --help > "$TMP/help.txt"
grep -q "step:from=A,to=B,at=T" "$TMP/help.txt" || fail "help lacks the step syntax"
grep -q "prbs:low=A,high=B,order=N,clock=C" "$TMP/help.txt" || fail "help lacks the prbs syntax"
grep -q "ipa-position" "$TMP/help.txt" || fail "help lacks the plant list"

# The paper's step test on the IPA simulator: CSV with t, u, y and chamber pressures.
"$PNEUMID" simulate --plant ipa --input step:from=0.61,to=82,at=1.0 --duration 4 --Ts 0.01 \
  --seed 3 -o "$TMP/ipa.csv" > "$TMP/out.txt"
grep -q "written: $TMP/ipa.csv" "$TMP/out.txt" || fail "summary does not name the file"
head -3 "$TMP/ipa.csv" | grep -q "^t \[s\],u \[%\],y \[N\],p_a \[Pa\],p_b \[Pa\]$" || fail "CSV header"
rows=$(grep -vc "^#\|^t " "$TMP/ipa.csv")
[ "$rows" -eq 401 ] || fail "expected 401 rows, got $rows"
# Force before the step about 0 N, at the end about 129 N (docs/paper.md, reference value 4).
awk -F, '!/^#/ && !/^t/ { if ($1 > 0.5 && $1 < 1.0 && ($3 < -1 || $3 > 1)) bad = 1;
  if ($1 > 3.5 && ($3 < 124 || $3 > 134)) bad = 1 } END { exit bad }' "$TMP/ipa.csv" \
  || fail "IPA step does not go from ~0 to ~129 N"

# Same seed, same data; another seed, other noise.
"$PNEUMID" simulate --plant ipa --duration 2 --seed 3 -o "$TMP/a.csv" > /dev/null
"$PNEUMID" simulate --plant ipa --duration 2 --seed 3 -o "$TMP/b.csv" > /dev/null
"$PNEUMID" simulate --plant ipa --duration 2 --seed 4 -o "$TMP/c.csv" > /dev/null
cmp -s "$TMP/a.csv" "$TMP/b.csv" || fail "same seed gave different data"
! cmp -s "$TMP/a.csv" "$TMP/c.csv" || fail "different seeds gave the same data"

# MAT output, averaged PWM mode, JSON summary.
"$PNEUMID" simulate --plant ipa --mode averaged --duration 2 -o "$TMP/ipa.mat" --json > "$TMP/sum.json"
[ -s "$TMP/ipa.mat" ] || fail "no MAT file"
grep -q '"samples": 201' "$TMP/sum.json" || fail "JSON summary lacks samples"
grep -q 'averaged' "$TMP/sum.json" || fail "JSON summary lacks the PWM mode"

# Linear plants: the paper's ARX model, an inline FOPDT, PRBS and staircase inputs, noise.
"$PNEUMID" simulate --plant arx-paper --input prbs:low=0,high=80,order=7,clock=0.05 \
  --duration 3 -o "$TMP/arx.csv" > /dev/null
"$PNEUMID" simulate --plant fopdt:K=1.6,tau=0.245,theta=0.001 --noise 0.5 \
  --input "staircase:levels=0 20 40,dwell=1" --duration 3 > "$TMP/stdout.csv"
grep -q "^t \[s\],u,y,y_true$" "$TMP/stdout.csv" || fail "CSV on stdout without -o"

# Position mode and a parameter file.
cat > "$TMP/ipa.toml" <<'TOML'
[pwm]
frequency = 100.0
TOML
"$PNEUMID" simulate --plant ipa-position --plant-config "$TMP/ipa.toml" --input step:to=100,at=0.2 \
  --duration 1 -o "$TMP/pos.csv" > "$TMP/pos.txt"
grep -q "position mode, switching PWM 100 Hz" "$TMP/pos.txt" || fail "config file not used"
head -3 "$TMP/pos.csv" | grep -q "y \[m\]" || fail "position output unit"

# --sample-time is an alias of --Ts.
"$PNEUMID" simulate --plant arx-paper --duration 0.5 --sample-time 0.01 -o "$TMP/alias.csv" > /dev/null \
  || fail "--sample-time alias"
[ "$(grep -vc "^#\|^t " "$TMP/alias.csv")" -eq 51 ] || fail "--sample-time alias: rows"

# Errors: clear message on stderr, non-zero exit.
simulate_error() {
  local pattern=$1; shift
  expect_error "simulate $*" "$pattern" simulate "$@"
}
simulate_error "unknown plant 'nope'" --plant nope
simulate_error "key 'to': not a finite number" --input step:to=x
simulate_error "unknown kind 'square'" --input square:f=1
simulate_error "--duration: must be > 0, got 0" --duration 0
simulate_error "duration must be at least one sample period" --duration 0.001
simulate_error "--Ts: must be > 0, got 0" --Ts 0
simulate_error "--noise: must be >= 0, got -1" --noise -1
printf '[valves]\nfoo = 1\n' > "$TMP/bad.toml"
simulate_error "bad.toml:2:7: unknown key 'valves.foo'" --plant-config "$TMP/bad.toml"
simulate_error "missing.toml" --plant-config "$TMP/missing.toml"
simulate_error "applies to the ipa plant only" --plant arx-paper --mode averaged
simulate_error "discrete model has Ts = 0.01" --plant arx-paper --Ts 0.02

# Signals far beyond their sample time: bounded time, defined results, clear errors.
timeout 30 "$PNEUMID" simulate --plant fopdt-paper --input prbs:order=32,clock=1e-9 --duration 1 \
  -o "$TMP/fast_prbs.csv" >/dev/null || fail "prbs with a 1 ns clock: no result in 30 s"
simulate_error "beyond the exact integers of a double" --plant fopdt-paper \
  --input prbs:order=7,clock=1e-300 --duration 1
"$PNEUMID" simulate --plant fopdt-paper --input "staircase:levels=1 2,dwell=1e-300" \
  --duration 0.05 -o "$TMP/stairs.csv" >/dev/null || fail "staircase with dwell 1e-300"
[ "$(grep -v '^#\|^t' "$TMP/stairs.csv" | tail -1 | cut -d, -f2)" = "2" ] \
  || fail "staircase with dwell 1e-300: last level expected"
simulate_error "above the Nyquist frequency 500 Hz" --plant fopdt-paper \
  --input chirp:from=0,to=1,f0=1,f1=600 --Ts 0.001 --duration 1
"$PNEUMID" simulate --plant fopdt-paper --input "staircase:levels=0,1,2,dwell=0.01" \
  --duration 0.05 -o "$TMP/comma.csv" >/dev/null || fail "levels separated by commas"
finish
