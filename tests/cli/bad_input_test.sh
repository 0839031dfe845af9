#!/usr/bin/env bash
# CLI test of hostile and malformed input files: each is refused quickly with
# a short message that says what is wrong (and quotes user data only as an
# excerpt).
# Usage: bash bad_input_test.sh /path/to/pneumid
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh" "$@"

# expect_short_error NAME "stderr substring" ARGS...: as expect_error, and the
# error message is short (user data is not echoed whole).
expect_short_error() {
  expect_error "$@"
  local size
  size=$(wc -c <"$TMP/err")
  [ "$size" -lt 2000 ] || fail "$1: error message is $size bytes long"
}

# A good step test to derive the bad ones from.
awk 'BEGIN { print "t,u,y"; for (k = 0; k < 200; k++) { t = k * 0.01; u = (k < 30) ? 0 : 1;
       y = (k < 30) ? 0 : 1 - exp(-(t - 0.30) / 0.245); printf "%.2f,%g,%.6f\n", t, u, y } }' \
  >"$TMP/good.csv"

# A 10 MB cell is quoted as its first bytes and its size.
$PY -c "
import sys
sys.stdout.write('t,u,y\n0,0,' + 'x' * 10_000_000 + '\n')" >"$TMP/cell.csv"
expect_short_error "10 MB cell" "not a number: 'xxxx" info "$TMP/cell.csv"
# A first word that is no command is named, with the closest command.
expect_error "misspelt command" "unknown command 'identfy'; did you mean 'identify'?" identfy data.csv
expect_error "unknown command" "unknown command 'frobnicate' (commands: app, bode," frobnicate
expect_error "10 MB cell size" "... (10000000 bytes)" info "$TMP/cell.csv"

# Values near the double range: named as overflow or extreme scale, not as
# a missing step.
awk -F, 'NR == 1 { print; next } { printf "%s,%s,%.17g\n", $1, $2, $3 * 1e308 }' \
  "$TMP/good.csv" >"$TMP/huge.csv"
expect_short_error "1e308 values" "output column 'y': values range from 0 to 9.9899e+307" \
  identify "$TMP/huge.csv" --method reaction-curve
expect_error "1e308 overflow" "overflow" identify "$TMP/huge.csv" --method arx
awk -F, 'NR == 1 { print; next } { printf "%s,%s,%.17g\n", $1, $2, $3 * 1e-300 }' \
  "$TMP/good.csv" >"$TMP/tiny.csv"
expect_short_error "1e-300 values" "extreme scale" identify "$TMP/tiny.csv" --method reaction-curve

# UTF-16 and binary files.
iconv -f UTF-8 -t UTF-16 "$TMP/good.csv" >"$TMP/utf16.csv"
expect_short_error "UTF-16" "the file is UTF-16LE text" info "$TMP/utf16.csv"
head -c 3000 "$PNEUMID" >"$TMP/binary.csv"
expect_short_error "binary" "this is a binary file" info "$TMP/binary.csv"

# A 5 MB line of numbers without a header: bounded time and message.
$PY -c "
import sys
sys.stdout.write(','.join(['1.25'] * 1_000_000) + '\n')" >"$TMP/line.csv"
start=$(date +%s)
expect_short_error "headerless line" "header row is 4999999 bytes long" info "$TMP/line.csv"
[ $(($(date +%s) - start)) -le 5 ] || fail "headerless line took more than 5 s"

# MAT files: truncated, and a small file claiming a huge variable.
$PY - "$TMP" <<'PY'
import sys, numpy as np, scipy.io as sio
d = sys.argv[1]
t = np.arange(100) * 0.01
sio.savemat(d + "/full.mat", {"t": t, "u": np.ones(100), "y": t})
data = open(d + "/full.mat", "rb").read()
open(d + "/cut.mat", "wb").write(data[:len(data) - 100])
# One variable whose dimensions claim 2^31 x 2^31 doubles, in 1110 bytes.
huge = bytearray(data[:1110])
import struct
struct.pack_into("<ii", huge, 128 + 8 + 16 + 8, 0x7FFFFFFF, 0x7FFFFFFF)
open(d + "/huge.mat", "wb").write(bytes(huge))
PY
expect_short_error "truncated .mat" "the file is truncated" info "$TMP/cut.mat"
start=$(date +%s)
expect_short_error "huge .mat" "claims dimensions 2147483647x2147483647" info "$TMP/huge.mat"
[ $(($(date +%s) - start)) -le 5 ] || fail "huge .mat took more than 5 s"

# A missing file and an unknown column of a file: input.
expect_short_error "file:/nonexistent" "/nonexistent: cannot open: No such file" \
  simulate --plant fopdt-paper --input file:/nonexistent --duration 1
expect_short_error "col=" "unknown input column 'p'" \
  simulate --plant fopdt-paper --input "file:$TMP/good.csv,col=p" --duration 1
grep -q "output" "$TMP/err" && fail "col= error calls the input column an output: $(cat "$TMP/err")"

# Integers out of range in a TOML configuration are refused, not wrapped.
printf '[loop]\npriority = 4294967376\n' >"$TMP/rt.toml"
expect_short_error "priority wraps" "rt.toml:2:12: [loop] priority = 4294967376 is out of range" \
  run --config "$TMP/rt.toml" --fast --duration 0.1
finish
