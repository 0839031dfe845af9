#!/usr/bin/env bash
# Linear models of a real process from measured data, checked on held-out data.
#
# The data are the cascaded tanks benchmark (data/tanks/README.md): pump
# voltage in, lower-tank water level out, both in V, Ts = 4 s; one record
# to estimate, another to validate.
#
# Usage: bash examples/cli/identify_tanks.sh [PNEUMID] [OUTDIR]
# Writes OUTDIR/tanks.json (the models), identify.png, validate_oe.png.
source "$(dirname "${BASH_SOURCE[0]}")/common.sh" "$@"
EST=$ROOT/data/tanks/estimation.csv
VAL=$ROOT/data/tanks/validation.csv

# What is in the file: samples, sample time, ranges (the level tops out at
# 10 V where the upper tank overflows).
"$PNEUMID" info "$EST"

# Five model structures at once; each is estimated on EST and ranked by its
# simulation fit on VAL. The polynomial models choose their operating point
# (u0, y0) themselves (--operating-point auto): here the records' means.
# The table goes to the terminal, the models (best first) to tanks.json.
"$PNEUMID" identify "$EST" -m arx,oe,bj,iv4,fit-p2d --validation "$VAL" \
  -o "$OUT/tanks.json" --plot "$OUT/identify.png"

# The best model must simulate the held-out record well (today: iv4, 72.6 %).
check "j['models'][0]['validation_fit_percent'] > 70" \
  "best validation fit above 70 %" "$OUT/tanks.json"

# Each of OE, BJ and IV4 simulated on the validation record from rest at its
# operating point: RMSE in V (today 0.575-0.591 V) and the residual tests.
for m in oe bj iv4; do
  "$PNEUMID" validate "$OUT/tanks.json#$m" "$VAL" --json > "$OUT/validate_$m.json"
  echo "$m: validation fit $(json "$OUT/validate_$m.json" "round(j['fit_percent'], 2)") %," \
    "RMSE $(json "$OUT/validate_$m.json" "round(j['rmse'], 4)") V"
  check "j['rmse'] < 0.62" "$m: validation RMSE below 0.62 V" "$OUT/validate_$m.json"
done

# A figure of the OE model on the validation data and its residual tests.
"$PNEUMID" validate "$OUT/tanks.json#oe" "$VAL" --plot "$OUT/validate_oe.png"
[ -s "$OUT/validate_oe.png" ] || { echo "no validation figure" >&2; exit 1; }
if [ -n "${2:-}" ]; then echo "outputs in $OUT"; fi
echo "identify_tanks: all checks passed"
