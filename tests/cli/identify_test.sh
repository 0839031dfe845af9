#!/usr/bin/env bash
# pneumid identify: table, --json contract, -o, --plot, errors on bad data.
# Usage: bash identify_test.sh /path/to/pneumid   (cwd: a scratch/build directory)
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh" "$@"
DATA=$SRC/tests/identify/data

check_help identify "-m,--method,--methods" "--Ts,--sample-time" "-o,--output" --plot

# Human table, best fit first.
"$PNEUMID" identify "$DATA/fopdt.csv" --method smith,reaction-curve,fit-p1d > "$TMP/table.txt" \
  || fail "identify table"
grep -q "fit-p1d" "$TMP/table.txt" || fail "table lacks fit-p1d"
first=$(awk 'NR==3 {print $1}' "$TMP/table.txt")
[ "$first" = "fit-p1d" ] || fail "best model first expected fit-p1d, got $first"

# JSON contract: {"models": [{method, structure, params{K,tau,theta}, tf{num,den,Ts,delay}, fit_percent}]}
"$PNEUMID" identify "$DATA/fopdt.csv" --method reaction-curve,fit-p1d,ptn --order 2 --json \
  > "$TMP/out.json" || fail "identify --json"
# --json -o FILE: the models go to the file, stdout gets a short summary (the
# file name and each model's method, structure and fit), not the same JSON twice.
"$PNEUMID" identify "$DATA/fopdt.csv" --methods reaction-curve,fit-p1d,ptn --order 2 --json \
  -o "$TMP/models.json" > "$TMP/brief.json" || fail "identify --json -o"
$PY - "$TMP/out.json" "$TMP/models.json" "$TMP/brief.json" "$TMP/models.json" <<'PYEOF' || fail "JSON contract"
import json, sys
j = json.load(open(sys.argv[1]))
assert json.load(open(sys.argv[2])) == j, "-o file differs from --json without -o"
brief = json.load(open(sys.argv[3]))
assert brief["output"] == sys.argv[4], brief
assert [m["method"] for m in brief["models"]] == [m["method"] for m in j["models"]], brief
assert {"method", "structure", "fit_percent", "flags"} <= set(brief["models"][0]), brief
assert brief["best"] == brief["models"][0]["method"] and brief["termination"] == "success", brief
models = j["models"]
assert [m["method"] for m in models][0] == "fit-p1d", models[0]["method"]
assert j["best"] == "fit-p1d" and j["failures"] == [] and j["termination"] == "success", j
# Ranked: models without flags first, then by fit (estimation data here).
def group(m):
    names = {f["flag"] for f in m["flags"]}
    return 0 if not names else 1 if names == {"residuals_not_white"} else 2
keys = [(group(m), -m["fit_percent"]) for m in models]
assert keys == sorted(keys), keys
for m in models:
    for key in ("method", "structure", "params", "tf", "fit_percent", "iae", "flags",
                "operating_point", "termination"):
        assert key in m, key
    for key in ("num", "den", "Ts", "delay"):
        assert key in m["tf"], key
rc = [m for m in models if m["method"] == "reaction-curve"][0]
assert rc["structure"] == "FOPDT"
p = rc["params"]
# Recorded plant: K = 2.5, tau = 1.5 s, theta = 0.413 s (gen_synthetic_steps.py).
assert abs(p["K"] - 2.5) < 0.05, p
assert abs(p["tau"] + p["theta"] - 1.913) < 0.05, p
assert abs(rc["tf"]["delay"] - p["theta"]) < 1e-12
ptn = [m for m in models if m["method"] == "ptn"][0]
assert ptn["structure"] == "PT2" and len(ptn["params"]["a"]) == 3, ptn
fit = models[0]["params"]
assert abs(fit["K"] - 2.5) < 0.05 and abs(fit["tau"] - 1.5) < 0.03, fit
PYEOF

# --plot writes a PNG.
"$PNEUMID" identify "$DATA/sopdt.csv" --method sopdt,fit-p2d --plot "$TMP/fig.png" > /dev/null \
  || fail "identify --plot"
check_png "$TMP/fig.png"
expect_error "plot extension" "must end in .png or .svg" identify "$DATA/fopdt.csv" --plot "$TMP/fig.bmp"

# Errors: unknown method, no step, not settled; non-zero exit and a message on stderr.
if "$PNEUMID" identify "$DATA/fopdt.csv" --method bogus > /dev/null 2> "$TMP/err"; then
  fail "unknown method accepted"
fi
grep -q "unknown method 'bogus'" "$TMP/err" || fail "unknown method message: $(cat "$TMP/err")"

$PY -c "
import math
with open('$TMP/flat.csv','w') as f:
    f.write('t,u,y\n')
    for k in range(300): f.write('%g,1,%g\n' % (0.01*k, math.sin(k)))
with open('$TMP/slow.csv','w') as f:
    f.write('t,u,y\n')
    for k in range(300):
        t = 0.01*k; u = 1.0 if k >= 20 else 0.0
        f.write('%g,%g,%g\n' % (t, u, u*(1-math.exp(-(t-0.2)/5.0)) if k >= 20 else 0.0))
"
if "$PNEUMID" identify "$TMP/flat.csv" --method reaction-curve > /dev/null 2> "$TMP/err"; then
  fail "data without a step accepted"
fi
grep -q "no step" "$TMP/err" || fail "no-step message: $(cat "$TMP/err")"
if "$PNEUMID" identify "$TMP/slow.csv" --method smith > /dev/null 2> "$TMP/err"; then
  fail "unsettled data accepted"
fi
grep -q "not settled" "$TMP/err" || fail "not-settled message: $(cat "$TMP/err")"

# Each method fails alone: on a PRBS record the step methods fail, ARX still
# runs; the failure and its reason go to stderr and JSON, the exit status is 0
# because a model was produced.
write_arx_prbs_data "$TMP/prbs.csv" 5
expect_ok "explicit list continues" identify "$TMP/prbs.csv" -m reaction-curve,arx --json
check_json "arx produced" '[m["method"] for m in j["models"]] == ["arx"]'
check_json "failure listed" 'j["failures"][0]["method"] == "reaction-curve" and j["failures"][0]["reason"] and j["termination"] == "partial"'
check_output "failure on stderr" "reaction-curve failed" "$TMP/err"
expect_error "no model at all" "no method produced a model" identify "$TMP/prbs.csv" -m reaction-curve,tangent
# --json still prints the failures (and the exit status is non-zero).
expect_error "no model, --json" "no method produced a model" identify "$TMP/prbs.csv" -m reaction-curve,tangent --json
check_json "failures in JSON" 'j["models"] == [] and j["best"] is None and [f["method"] for f in j["failures"]] == ["reaction-curve", "tangent"] and j["termination"] == "failure"'
# Two input columns (or none): an error naming them, not a model of the first.
$PY - "$TMP/prbs.csv" "$TMP/miso.csv" <<'PYEOF'
import sys
rows = [l.rstrip("\n").split(",") for l in open(sys.argv[1]) if not l.startswith("#")]
with open(sys.argv[2], "w") as f:
    f.write("t,u,u2,y\n")
    for k, r in enumerate(rows[1:]):
        f.write(f"{r[0]},{r[1]},{(k * 7919) % 13 - 6},{r[2]}\n")
PYEOF
expect_error "two inputs" "selects 2 input columns (u, u2)" identify "$TMP/miso.csv" --input-col u,u2 -m arx
expect_error "two inputs, validate" "selects 2 input columns (u, u2)" validate fopdt-paper "$TMP/miso.csv" --input-col u,u2
expect_error "two inputs, orders" "selects 2 input columns (u, u2)" orders "$TMP/miso.csv" --input-col u,u2
expect_error "no input" "time-series models (no input) are not available" identify "$TMP/miso.csv" --input-col '' -m arx
expect_ok "one of two inputs" identify "$TMP/miso.csv" --input-col u -m arx --json
# Without --method: the reaction curve on a step test, the methods for
# general inputs on any other record, with a warning saying why.
expect_ok "auto on a PRBS" identify "$TMP/prbs.csv" --json
check_json "auto: general methods" 'sorted(m["method"] for m in j["models"]) == ["arx", "bj", "fit-p1d", "iv4", "oe"] and j["warnings"] and "not a single step" in j["warnings"][0]'
check_output "auto warning on stderr" "identified with the methods for general inputs, fit-p1d, arx, oe, bj, iv4" "$TMP/err"
expect_ok "auto on a step test" identify "$DATA/fopdt.csv" --json
check_json "auto: reaction curve" '[m["method"] for m in j["models"]] == ["reaction-curve"] and j["warnings"] == []'

# A pole near z = -1 is flagged and never ranked best while a model without
# such a flag exists (no_convergence and residuals_not_white do not move a
# model back: its fit is the evidence); every model says why it stands where it does.
expect_ok "flags" identify "$TMP/prbs.csv" -m arx,oe,fit-p1d --json
check_json "trusted best" 'not {f["flag"] for f in j["models"][0]["flags"]} & {"nyquist_pole", "unstable", "not_finite"} and j["best"] == j["models"][0]["method"]'
check_json "rank reasons" 'all(m["rank_reason"].startswith("estimation fit") for m in j["models"])'

# Held-out validation: --split and --validation rank by the validation fit.
write_arx_prbs_data "$TMP/prbs2.csv" 6
expect_ok "split" identify "$TMP/prbs.csv" -m arx,fit-p1d --split 0.7 --json
check_json "split samples" 'j["estimation_samples"] == 2100 and j["validation_samples"] == 900 and j["ranked_by"] == "validation_fit_percent"'
check_json "validation fits" 'all("validation_fit_percent" in m for m in j["models"])'
expect_ok "validation file" identify "$TMP/prbs.csv" -m arx,fit-p1d --validation "$TMP/prbs2.csv"
check_output "validation column" "val fit %"
check_output "validation line" "validated on 3000 held-out samples"
expect_error "split and validation" "exclude each other" identify "$TMP/prbs.csv" -m arx --split 0.5 --validation "$TMP/prbs2.csv"
expect_error "split of 1" "--split" identify "$TMP/prbs.csv" -m arx --split 1
printf 't,valve,y\n0,1,2\n0.01,1,2\n0.02,1,2\n' > "$TMP/other.csv"
expect_error "validation columns" "other.csv" identify "$TMP/prbs.csv" -m arx --validation "$TMP/other.csv"

# One fit: validate on the estimation file gives the fit identify printed,
# with the process model's offset y0 applied.
expect_ok "fit-p1d to file" identify "$DATA/fopdt.csv" -m fit-p1d -o "$TMP/p1d.json" --json
fit=$($PY -c "import json; print('%.2f' % json.load(open('$TMP/p1d.json'))['models'][0]['fit_percent'])")
expect_ok "validate p1d" validate "$TMP/p1d.json" "$DATA/fopdt.csv"
check_output "same fit" "simulation fit: $fit %"

# A split whose rest holds one input level: ranked on it with a warning, on
# stderr and in --json; orders that do not apply to a method are said to.
expect_ok "one-level step" simulate --plant arx-paper --input step:from=0,to=50,at=1 --duration 4 \
  -o "$TMP/onestep.csv"
expect_ok "split at one level" identify "$TMP/onestep.csv" -m arx,fit-p1d --split 0.6
check_output "one-level warning" "warning: the last 40 % of $TMP/onestep.csv holds a constant input (u = 50 over" "$TMP/err"
expect_ok "split at one level, json" identify "$TMP/onestep.csv" -m arx,fit-p1d --split 0.6 --json
check_json "warnings key" 'len(j["warnings"]) == 1 and "holds a constant input" in j["warnings"][0]'
# A held-out part shorter than half the best model's settling time (the
# cascaded tanks' last 1 %: 10 samples against about 170): warned.
expect_ok "short held-out part" identify "$SRC/data/tanks/estimation.csv" -m oe --split 0.99 --json
check_json "short held-out warning" 'any("holds 10 samples (40 s), fewer than half of what the best-ranked model \x27oe\x27 takes to settle" in w for w in j["warnings"])'
expect_ok "long enough held-out part" identify "$SRC/data/tanks/estimation.csv" -m oe --split 0.8 --json
check_json "no short held-out warning" 'not any("takes to settle" in w for w in j["warnings"])'
expect_ok "no warnings" identify "$TMP/prbs.csv" -m arx --split 0.7 --json
check_json "empty warnings" 'j["warnings"] == []'
expect_ok "stairs" simulate --plant ipa --input "staircase:levels=10 40 70 25 55 85,dwell=1" --duration 6 \
  -o "$TMP/stairs.csv"
expect_ok "affine-narx --na" identify "$TMP/stairs.csv" -m affine-narx --na 2
check_output "affine-narx order warning" "affine-narx is first order" "$TMP/err"
finish
