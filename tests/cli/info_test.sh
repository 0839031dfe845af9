#!/usr/bin/env bash
# CLI test of `pneumid info`: a good file gives its summary; every bad input
# gives a non-zero exit and an error on stderr naming file, line and column.
# Usage: bash info_test.sh /path/to/pneumid
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh" "$@"
dir=$TMP

# A step test: duty 0.61 -> 82 % at t = 0.30 s, force rising to 129 N.
good="$dir/step.csv"
{
  echo "# reaction-curve test"
  echo "t,u [%],y [N]"
  awk 'BEGIN { for (k = 0; k < 200; k++) { t = k * 0.01; u = (k < 30) ? 0.61 : 82;
               y = (k < 30) ? 0 : 129 * (1 - exp(-(t - 0.30) / 0.245));
               printf "%.2f,%g,%.6f\n", t, u, y } }'
} >"$good"

expect_ok "good file" info "$good"
grep -q "samples: *200" "$dir/out" || fail "samples missing: $(cat "$dir/out")"
grep -q "sample time: *0.01 s" "$dir/out" || fail "sample time missing: $(cat "$dir/out")"
grep -q "uniform: *yes" "$dir/out" || fail "uniform missing"
grep -q "step: *input 'u' at t = 0.3 s (.*step.csv:33, sample 30): 0.61 -> 82 (size 81.39)" \
  "$dir/out" || fail "step line wrong: $(cat "$dir/out")"
grep -q "^y \[N\] *output" "$dir/out" || fail "output row missing"

expect_ok "json" info "$good" --json
/usr/bin/python3 - "$dir/out" <<'PY' || fail "json content"
import json, sys
j = json.load(open(sys.argv[1]))
assert j["samples"] == 200, j
assert abs(j["sample_time"] - 0.01) < 1e-12
assert j["uniform"] is True
assert j["step"]["index"] == 30 and j["step"]["line"] == 33
assert abs(j["step"]["time"] - 0.30) < 1e-12
assert abs(j["step"]["size"] - 81.39) < 1e-9
names = [c["name"] for c in j["channels"]]
assert names == ["t", "u", "y"], names
assert j["channels"][2]["unit"] == "N"
assert abs(j["channels"][2]["max"] - 129 * (1 - 2.718281828459045 ** (-1.69 / 0.245))) < 1e-5
PY

# Selection by index, semicolon delimiter, no time column.
printf 'a;b;c\n1;0;5\n2;1;6\n3;1;7\n' >"$dir/semi.csv"
expect_ok "by index" info "$dir/semi.csv" --time-col 0 --input-col 1 --output-col 2,0
expect_ok "sample time" info "$dir/semi.csv" --Ts 0.5 --input-col b --output-col c --json
grep -q '"sample_time": 0.5' "$dir/out" || fail "sample time 0.5: $(cat "$dir/out")"
# --sample-time stays an alias of --Ts.
expect_ok "sample time alias" info "$dir/semi.csv" --sample-time 0.5 --input-col b --output-col c --json
grep -q '"sample_time": 0.5' "$dir/out" || fail "--sample-time alias: $(cat "$dir/out")"
expect_error "negative Ts" "--Ts: must be >= 0, got -1" info "$dir/semi.csv" --Ts -1

# Non-uniform sampling: summary says so and how to resample; --strict fails.
printf 't,u,y\n0,0,0\n0.01,1,0\n0.02,1,1\n0.05,1,2\n0.06,1,3\n' >"$dir/gap.csv"
expect_ok "non-uniform" info "$dir/gap.csv"
grep -q "uniform: *no" "$dir/out" || fail "non-uniform not reported"
grep -qF -- "--resample 0.01 -o" "$dir/out" || fail "no resampling hint: $(cat "$dir/out")"
expect_error "strict" "gap.csv:5: column 't': sampling is not uniform" info "$dir/gap.csv" --strict
expect_ok "resample" info "$dir/gap.csv" --resample 0.01 -o "$dir/fixed.csv"
expect_ok "resampled is uniform" info "$dir/fixed.csv" --strict
grep -q "samples: *7" "$dir/out" || fail "resampled size: $(cat "$dir/out")"

# MAT round trip through --save (the older spelling of -o/--output).
expect_ok "save mat" info "$good" --window 0,1 --save "$dir/step.mat"
expect_ok "read mat" info "$dir/step.mat" --json
grep -q '"samples": 101' "$dir/out" || fail "mat samples: $(cat "$dir/out")"
# The window as the identification commands write it (T0:T1) gives the same.
expect_ok "window T0:T1" info "$good" --window 0:1 --json
grep -q '"samples": 101' "$dir/out" || fail "window 0:1 samples: $(cat "$dir/out")"
expect_error "window one value" "--window takes two times" info "$good" --window 1
expect_error "window text" "--window: T1 must be a time in seconds, got 'x'" info "$good" --window 0,x

# Every bad input: non-zero exit, message names file, line and column.
printf 't,u,y\n0,1,2\n0.01,nan,3\n' >"$dir/nan.csv"
expect_error "NaN" "nan.csv:3: column 'u': NaN" info "$dir/nan.csv"
printf 't,u,y\n0,1,2\n0.01,1,inf\n' >"$dir/inf.csv"
expect_error "Inf" "inf.csv:3: column 'y': infinite" info "$dir/inf.csv"
printf 't,u,y\n0,1,2\n0.01,abc,3\n' >"$dir/text.csv"
expect_error "non-numeric" "text.csv:3: column 'u': not a number: 'abc'" info "$dir/text.csv"
printf 't,u,y\n0,1,2\n0.01,1\n' >"$dir/ragged.csv"
expect_error "ragged" "ragged.csv:3: row has 2 cells but the header (line 1) has 3" info "$dir/ragged.csv"
printf 't,u,y\n0,1,2\n0.01,,2\n' >"$dir/missing.csv"
expect_error "missing cell" "missing.csv:3: column 'u': missing value" info "$dir/missing.csv"
printf 't,u,y\n0,1,2\n0.02,1,2\n0.01,1,2\n' >"$dir/order.csv"
expect_error "time order" "order.csv:4: column 't': time is not strictly increasing" info "$dir/order.csv"
: >"$dir/empty.csv"
expect_error "empty" "empty.csv:1: empty file" info "$dir/empty.csv"
printf '# comment\nt,u,y\n' >"$dir/header.csv"
expect_error "header only" "header.csv:2: header row only" info "$dir/header.csv"
expect_error "unknown column" "unknown output column 'F'; available columns: 't', 'u [%]', 'y [N]'" \
  info "$good" --output-col F
expect_error "missing file" "does not exist" info "$dir/nope.csv"
printf 'x' >"$dir/data.xlsx"
expect_error "extension" "unknown data file extension '.xlsx'" info "$dir/data.xlsx"
expect_error "not a mat file" "cannot open as a MAT file" info "$dir/nan.csv" --format mat
expect_error "bad delimiter" "--delimiter" info "$good" --delimiter x
expect_error "bad decimate" "--decimate: must be an integer >= 1, got 0" info "$good" --decimate 0
expect_error "bad resample" "--resample: must be >= 0, got -0.5" info "$good" --resample=-0.5

check_help info --input-col "--Ts,--sample-time" "-o,--output,--save"
finish
