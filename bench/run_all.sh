#!/usr/bin/env bash
# Runs every Google Benchmark program of a build tree and the side-by-side
# scripts, writing JSON results to BUILD/bench/results/. Usage:
#   bash bench/run_all.sh [BUILD_DIR]
set -euo pipefail
BUILD=${1:-build}
OUT="$BUILD/bench/results"
mkdir -p "$OUT"
for b in "$BUILD"/bench/*_benchmark; do
  [ -x "$b" ] || continue
  name=$(basename "$b")
  echo "== $name"
  "$b" --benchmark_min_time=0.2 --benchmark_out="$OUT/$name.json" --benchmark_out_format=json
done
echo "== ARX against Octave's control package"
bash bench/arx_vs_octave.sh "$BUILD" || echo "arx_vs_octave: skipped"
echo "== pneumid app requests"
/usr/bin/python3 bench/app_requests.py "$BUILD/pneumid" | tee "$OUT/app_requests.txt" || echo "app_requests: skipped"
echo "results in $OUT/"
