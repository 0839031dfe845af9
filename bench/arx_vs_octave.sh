#!/usr/bin/env bash
# ARX(3,3,1) on 10^6 samples: pneumid (blocked Householder QR, one thread)
# against Octave's control package `arx`, side by side on the same data file.
# Usage: bench/arx_vs_octave.sh [BUILD_DIR] [N]
#   BUILD_DIR  contains bench/arx_benchmark (default: build)
#   N          number of samples (default 1000000)
# Installs octave and octave-control with apt-get when they are missing; when
# that is impossible the Octave column is skipped with a message.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
build="${1:-build}"
n="${2:-1000000}"
bench="$build/bench/arx_benchmark"
[[ -x "$bench" ]] || { echo "error: $bench not found (build the arx_benchmark target)" >&2; exit 1; }
py=/usr/bin/python3
data="$(mktemp /tmp/pneumid_arx_vs_octave.XXXXXX.csv)"
trap 'rm -f "$data"' EXIT

# Data of the paper's ARX(3,3,1) model (Eq. 5): random binary input held for
# 3 samples (10 / 90 %), white equation noise of standard deviation 0.5 N.
"$py" - "$data" "$n" <<'PY'
import sys
import numpy as np
from scipy.signal import lfilter
path, n = sys.argv[1], int(sys.argv[2])
rng = np.random.default_rng(1)
u = np.repeat(np.where(rng.random(n // 3 + 1) > 0.5, 90.0, 10.0), 3)[:n]
a = [1, -0.60870, -0.27020, -0.06021]
y = lfilter([0, 0.03938, 0.04506, 0.01286], a, u) + lfilter([1], a, rng.normal(0, 0.5, n))
np.savetxt(path, np.c_[u, y], delimiter=",", header="u,y", comments="", fmt="%.10g")
PY

out="$(PNEUMID_BENCH_DATA="$data" "$bench" --benchmark_filter="BM_Arx331/1000000$" \
        --benchmark_repetitions=5 --benchmark_report_aggregates_only=true 2>/dev/null)"
line="$(grep 'BM_Arx331/1000000_median' <<<"$out")"
# Columns: name, real time, unit, cpu time, unit, ...
p_cpu_ms="$(awk '{print $4}' <<<"$line")"
p_wall_ms="$(awk '{print $2}' <<<"$line")"
label="$(PNEUMID_BENCH_DATA="$data" "$bench" --benchmark_filter="BM_Arx331/1000000$" \
          --benchmark_min_time=0.01 2>/dev/null | grep -o 'N=.*' || true)"
echo "data: $n samples, ARX(3,3,1), Ts = 0.01 s"
echo "pneumid: median CPU time ${p_cpu_ms} ms (wall ${p_wall_ms} ms), one thread"
echo "pneumid estimate: $label"

if ! command -v octave >/dev/null || ! octave --no-gui --eval "pkg load control" >/dev/null 2>&1; then
  echo "Octave or its control package is missing: trying apt-get install octave octave-control"
  if [[ $(id -u) -eq 0 ]]; then apt_get="apt-get"; else apt_get="sudo -n apt-get"; fi
  $apt_get install -y octave octave-control >/dev/null 2>&1 || true
fi
if command -v octave >/dev/null && octave --no-gui --eval "pkg load control" >/dev/null 2>&1; then
  oct="$(octave --no-gui --norc -q "$here/arx_vs_octave.m" "$data" 2>/dev/null)"
  o_s="$(awk '/^octave_seconds/ {print $2}' <<<"$oct")"
  echo "octave control arx: best of 3 $(awk -v s="$o_s" 'BEGIN{printf "%.1f", s*1000}') ms"
  grep -E '^octave_(a|b)' <<<"$oct" | sed 's/^/  /'
  awk -v s="$o_s" -v p="$p_cpu_ms" 'BEGIN{printf "speed-up (Octave / pneumid CPU time): %.0fx\n", s*1000/p}'
else
  echo "Octave column skipped: octave with the control package is not available and could not be installed"
fi
