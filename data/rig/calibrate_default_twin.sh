#!/bin/sh
# Calibrates the default IPA twin (config/ipa_default.toml) to the paper's rig
# data (gen_rig_data.py: Eq. 5's response to the paper's step), starting from
# twin_start.toml (the bore and the sensor filter's time constant are free),
# and checks it against Eq. 5's response to the PRBS.
# Usage: data/rig/calibrate_default_twin.sh [PNEUMID] [OUTPUT.toml]
set -e
here=$(cd "$(dirname "$0")" && pwd)
pneumid=${1:-pneumid}
out=${2:-twin.toml}
"$pneumid" calibrate "$here/eq5_step.csv" --plant-config "$here/twin_start.toml" --free bore,pressure_filter_time_constant \
  --validation "$here/eq5_prbs.csv" -o "$out"
