#!/usr/bin/env bash
# CLI test of --confidence K on `pneumid step`, `pneumid bode` and `pneumid
# report`: bands of K standard deviations of models identified by `pneumid
# identify -o`, the standard deviations in the JSON output against a Monte
# Carlo estimate (parameters drawn from the covariance in the model file,
# numpy, fixed seed), and errors for bad K and models without a covariance.
# Usage: bash confidence_test.sh /path/to/pneumid
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh" "$@"
dir=$TMP
data=$SRC/data/ipa_step.csv

expect_ok "identify" identify "$data" -m arx,fit-p1d,reaction-curve -o "$dir/m.json"
check_json "covariance of arx" \
  "[m.get('covariance', {}).get('names') for m in j['models'] if m['method'] == 'arx'] == [['a1','a2','a3','b1','b2','b3']]" \
  "$dir/m.json"
check_json "fit-p1d covariance" \
  "[len(m['covariance']['matrix']) for m in j['models'] if m['method'] == 'fit-p1d'] == [4]" \
  "$dir/m.json"
check_json "no covariance for reaction-curve" \
  "[('covariance' in m) for m in j['models'] if m['method'] == 'reaction-curve'] == [False]" \
  "$dir/m.json"

# Step: plot with a band, JSON with the response and its standard deviation
# on a grid of the sample time (where the continuous form equals the discrete one).
expect_ok "step plot" step --model "$dir/m.json#arx" --confidence 3 --plot "$dir/step.png"
check_png "$dir/step.png"
check_output "step text band" "(+-3 sd, max +-"
expect_ok "step svg" step --model "$dir/m.json#arx" --confidence 2 --plot "$dir/step.svg"
check_svg "$dir/step.svg"
grep -qF "±2 sd" "$dir/step.svg" || fail "step.svg: no '±2 sd' band in the legend"
expect_ok "step json" step --model "$dir/m.json#arx" --confidence 3 --t-final 1 --dt 0.01 --json
cp "$TMP/out" "$dir/step.json"
check_json "step json keys" \
  "j['confidence'] == 3 and len(j['t']) == len(j['y']) == len(j['std']) == 101 and j['std'][0] == 0 and j['std'][-1] > 0"
$PY - "$dir/m.json" "$dir/step.json" <<'PYEOF' || fail "step std vs Monte Carlo"
import json, sys
import numpy as np
from scipy.signal import lfilter
m = [x for x in json.load(open(sys.argv[1]))["models"] if x["method"] == "arx"][0]
s = json.load(open(sys.argv[2]))
a, b, nk = np.array(m["params"]["a"]), np.array(m["params"]["b"]), m["params"]["nk"]
names, P = m["covariance"]["names"], np.array(m["covariance"]["matrix"])
theta = np.concatenate([a[1:], b[nk:]])
rng = np.random.default_rng(1)
samples = rng.multivariate_normal(theta, P, size=4000)
n = len(s["t"])
y = np.empty((len(samples), n))
for i, th in enumerate(samples):
    aa = np.concatenate([[1.0], th[:len(a) - 1]])
    bb = np.concatenate([np.zeros(nk), th[len(a) - 1:]])
    y[i] = lfilter(bb, aa, np.ones(n))
mc = y.std(axis=0, ddof=1)
sd = np.array(s["std"])
rel = np.abs(sd[5:] - mc[5:]) / mc[5:]
print(f"step std at t = {s['t'][-1]:g} s: Gauss {sd[-1]:.6g}, Monte Carlo {mc[-1]:.6g}; "
      f"max relative difference {rel.max():.3f} over t >= 0.05 s")
assert rel.max() < 0.10, rel.max()
PYEOF

# Bode: plot and JSON with the standard deviations of magnitude and phase.
expect_ok "bode plot" bode --model "$dir/m.json#fit-p1d" --confidence 3 --plot "$dir/bode.png"
check_png "$dir/bode.png"
expect_ok "bode json" bode --model "$dir/m.json#arx" --confidence 1 --points 20 --json
check_json "bode json keys" \
  "j['confidence'] == 1 and len(j['magnitude_db_std']) == len(j['phase_deg_std']) == len(j['omega']) == 20 and all(v > 0 for v in j['magnitude_db_std'])"
check_help step --confidence
check_help bode --confidence

# Report: the step and Bode figures carry the bands.
expect_ok "report" report "$data" -m arx,fit-p1d,reaction-curve --confidence 3 -o "$dir/rep"
check_output "report bands" "±3 standard deviations" "$dir/rep/report.html"
check_output "report command" "--confidence 3" "$dir/rep/report.html"
check_output "report models.json covariance" '"covariance"' "$dir/rep/models.json"

# Bad K, models without a covariance, models not from an identify file.
expect_error "K = 0" "--confidence: must be > 0, got 0" step --model "$dir/m.json#arx" --confidence 0
expect_error "K < 0" "--confidence: must be > 0, got -2" bode --model "$dir/m.json#arx" --confidence=-2
expect_error "K not a number" "--confidence" report "$data" --confidence abc -o "$dir/rep2"
expect_error "no covariance" "the 'reaction-curve' model of" \
  step --model "$dir/m.json#reaction-curve" --confidence 3
expect_error "not an identify file" "--confidence needs a model of a file written by" \
  bode --model fopdt-paper --confidence 3
finish
