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
assert set(brief["models"][0]) == {"method", "structure", "fit_percent"}, brief
models = j["models"]
assert [m["method"] for m in models][0] == "fit-p1d", models[0]["method"]
fits = [m["fit_percent"] for m in models]
assert fits == sorted(fits, reverse=True), fits
for m in models:
    for key in ("method", "structure", "params", "tf", "fit_percent", "iae"):
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
finish
