#!/usr/bin/env bash
# pneumid report: writes a self-contained HTML report, which headless Chromium
# renders with every plot and table present (DOM counts, screenshot size and
# content), and rejects bad input with a clear error.
# Usage: bash report_test.sh /path/to/pneumid   (cwd: build directory)
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh" "$@"
WORK=$TMP/work
mkdir "$WORK"

# The paper's step test on a first-order plant 1.6 / (0.245 s + 1): duty
# 0.61 -> 82 % at t = 0.5 s, force with 0.3 N Gaussian noise (seeded).
"$PY" - "$WORK/step.csv" <<'PYEOF' || fail "could not write the test data"
import sys, numpy as np
rng = np.random.default_rng(5)
Ts, n, ks = 0.01, 300, 50
t = np.arange(n) * Ts
u = np.where(np.arange(n) >= ks, 82.0, 0.61)
y = np.where(t > ks * Ts, 1.6 * (82.0 - 0.61) * (1 - np.exp(-(t - ks * Ts) / 0.245)), 0.0)
y += rng.normal(0.0, 0.3, n)
with open(sys.argv[1], "w") as f:
    f.write("t,u,F\n")
    for row in zip(t, u, y):
        f.write("%.4f,%.4f,%.6f\n" % row)
PYEOF

# 1. The report is written and the summary is printed.
"$PNEUMID" report "$WORK/step.csv" --output-col F -o "$WORK/out" >"$WORK/stdout" 2>"$WORK/stderr" \
  || { cat "$WORK/stderr" >&2; fail "pneumid report exited with $?"; }
grep -q "reaction-curve" "$WORK/stdout" || fail "summary does not list reaction-curve"
grep -q "report success" "$WORK/stdout" || { cat "$WORK/stdout"; fail "report not successful"; }
[ -s "$WORK/out/report.html" ] || fail "report.html missing"
[ -s "$WORK/out/models.json" ] || fail "models.json missing"
"$PY" -c "import json,sys; d=json.load(open(sys.argv[1])); assert len(d['models'])==3, d" \
  "$WORK/out/models.json" || fail "models.json does not hold 3 models"
# Self-contained: no external resources.
if grep -Eq '<(script|link|img)[ >]|src="http|href="http' "$WORK/out/report.html"; then
  fail "report.html refers to external resources"
fi
grep -q "pneumid report .*step.csv --output-col F" "$WORK/out/report.html" \
  || fail "report.html lacks the command that reproduces it"

# 2. --json
"$PNEUMID" report "$WORK/step.csv" --output-col F --methods reaction-curve,arx -o "$WORK/out2" \
  --json >"$WORK/json" || fail "--json run failed"
"$PY" -c "
import json,sys
d=json.load(open(sys.argv[1]))
assert d['termination']=='success', d
assert [m['method'] for m in d['models']]==['reaction-curve','arx'], d['models']
assert d['figures']==4 and d['tables']==3, d
" "$WORK/json" || fail "--json output wrong"

# The default methods (auto): the paper's three on the step test above, the
# methods for general inputs on a record that is not a step test (the
# cascaded tanks), with a warning that says why.
"$PNEUMID" report "$SRC/data/tanks/estimation.csv" -o "$WORK/tanks" --json >"$WORK/tanks.json" \
  2>"$WORK/tanks.err" || fail "report on the tanks exited with $?: $(cat "$WORK/tanks.err")"
"$PY" -c "
import json,sys
d=json.load(open(sys.argv[1]))
assert sorted(m['method'] for m in d['models'])==['arx','bj','fit-p1d','iv4','oe'], d['models']
" "$WORK/tanks.json" || fail "report auto on the tanks: not the methods for general inputs"
grep -q "the input is not a single step" "$WORK/tanks.err" || fail "report auto: no warning"
grep -q -- "--method auto" "$WORK/tanks/report.html" || fail "report auto: command line"
"$PNEUMID" report "$WORK/step.csv" --output-col F -o "$WORK/out6" --json >"$WORK/json6" 2>"$WORK/err6"
"$PY" -c "
import json,sys
d=json.load(open(sys.argv[1]))
assert sorted(m['method'] for m in d['models'])==['arx','ptn','reaction-curve'], d['models']
" "$WORK/json6" || fail "report auto on a step test: not reaction-curve, ptn, arx"
[ -s "$WORK/err6" ] && fail "report auto on a step test warned: $(cat "$WORK/err6")"

# Canonical flag names, the older ones as aliases; the report's command line uses the canonical ones.
grep -q -- "--method reaction-curve,arx --output-dir" "$WORK/out2/report.html" \
  || fail "report command line does not use --method/--output-dir"
expect_error "max-lag" "--max-lag: must be an integer >= 1, got 0" report "$WORK/step.csv" \
  --output-col F --output-dir "$WORK/o5" --max-lag 0
check_help report "-m,--method,--methods" "-o,--output-dir" "--Ts,--sample-time"

# 3. Headless Chromium renders the page: DOM has every plot and table.
CHROME=$(command -v chromium || command -v chromium-browser || true)
# scripts/setup installs it (make test runs setup): its absence is a failure.
[ -n "$CHROME" ] || die "chromium not installed (scripts/setup installs it)"
FLAGS=(--headless --no-sandbox --disable-gpu --disable-quic --no-first-run
       --disable-background-networking --disable-component-update --disable-sync
       --user-data-dir="$WORK/chrome-profile")
timeout 120 "$CHROME" "${FLAGS[@]}" --dump-dom "file://$WORK/out/report.html" \
  >"$WORK/dom.html" 2>"$WORK/chrome.log" || { tail -5 "$WORK/chrome.log" >&2; fail "chromium --dump-dom failed"; }
"$PY" - "$WORK/dom.html" <<'PYEOF' || fail "rendered DOM lacks plots or tables"
import re, sys
dom = open(sys.argv[1]).read()
svgs = len(re.findall(r"<svg\b", dom))
tables = len(re.findall(r"<table\b", dom))
figs = len(re.findall(r'<figure class="plot"', dom))
print(f"DOM: {svgs} svg, {figs} figures, {tables} tables")
assert svgs == 4 and figs == 4, "expected 4 plots"
assert tables == 3, "expected 3 tables"
for caption in ("Identified parameters", "Fit to the data", "Dataset"):
    assert caption in dom, caption
# each figure has drawn content (cairo paths), not an empty svg
for body in re.findall(r"<svg\b.*?</svg>", dom, flags=re.S):
    assert body.count("<path") > 20, "a plot has almost no drawing"
PYEOF

# 4. Screenshot: big, and not blank (many distinct colours, plot-like content).
timeout 120 "$CHROME" "${FLAGS[@]}" --hide-scrollbars --window-size=1200,4200 \
  --screenshot="$WORK/shot.png" "file://$WORK/out/report.html" >>"$WORK/chrome.log" 2>&1 \
  || { tail -5 "$WORK/chrome.log" >&2; fail "chromium --screenshot failed"; }
"$PY" - "$WORK/shot.png" <<'PYEOF' || fail "screenshot check failed"
import os, sys
from PIL import Image
p = sys.argv[1]
size = os.path.getsize(p)
im = Image.open(p).convert("RGB")
w, h = im.size
small = im.resize((w // 4, h // 4))
colors = len(set(small.getdata()))
# fraction of rows that are not a single colour: text, plots, tables
rows = sum(1 for y in range(small.size[1])
           if len(set(small.crop((0, y, small.size[0], y + 1)).getdata())) > 3)
frac = rows / small.size[1]
print(f"screenshot {w}x{h}, {size} bytes, {colors} colours, {frac:.2f} of rows with content")
assert (w, h) == (1200, 4200)
assert size > 150_000, "screenshot too small: blank page?"
assert colors > 200, "too few colours for plots"
assert frac > 0.5, "most of the page is empty"
PYEOF

# 5. Bad input: clear errors, non-zero exit, no crash.
"$PNEUMID" report "$WORK/missing.csv" -o "$WORK/o3" 2>"$WORK/err" && fail "missing file accepted"
grep -q "missing.csv" "$WORK/err" || fail "error does not name the missing file"
"$PNEUMID" report "$WORK/step.csv" --output-col F --methods nonsense -o "$WORK/o4" 2>"$WORK/err" \
  && fail "unknown method accepted"
grep -q "nonsense" "$WORK/err" || fail "error does not name the unknown method"
"$PNEUMID" report "$WORK/step.csv" 2>/dev/null && fail "missing -o accepted"
finish
