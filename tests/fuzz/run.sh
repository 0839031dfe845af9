#!/usr/bin/env bash
# Builds the libFuzzer targets (tests/fuzz/*_fuzz.cpp) with clang into
# build-fuzz and runs each for a short budget from its committed seed corpus
# (tests/fuzz/corpus/<target>/). Any crash, sanitizer report, leak, input that
# runs longer than -timeout seconds or memory above -rss_limit_mb fails the run
# (exit status 1); the input that caused it is kept in
# build-fuzz/fuzz/artifacts/<target>/ and the log in build-fuzz/fuzz/<target>.log.
#
# Usage: tests/fuzz/run.sh [target ...]      (default: every target)
# Environment: FUZZ_SECONDS (budget per target, default 30), FUZZ_BUILD
# (build directory, default build-fuzz), JOBS (targets run side by side and
# build parallelism, default 2).
# Reproduce a finding: build-fuzz/fuzz/<target>_fuzz <artifact file>
set -euo pipefail
cd "$(dirname "$0")/../.."
root=$PWD
build=${FUZZ_BUILD:-build-fuzz}
budget=${FUZZ_SECONDS:-30}
jobs=${JOBS:-2}
all=(csv mat model signal udp realtime_config ipa_config)
if [ $# -gt 0 ]; then targets=("$@"); else targets=("${all[@]}"); fi

cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ -DPNEUMID_BUILD_FUZZ=ON \
  -DPNEUMID_BUILD_TESTS=OFF -DPNEUMID_BUILD_BENCHMARKS=OFF -DPNEUMID_BUILD_PYTHON=OFF >/dev/null
names=()
for t in "${targets[@]}"; do names+=("${t}_fuzz"); done
cmake --build "$build" -j"$jobs" --target "${names[@]}"

out=$root/$build/fuzz
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
export ASAN_OPTIONS=detect_leaks=1
run_one() {
  local t=$1
  local work=$out/corpus/$t artifacts=$out/artifacts/$t
  rm -rf "$artifacts"
  mkdir -p "$work" "$artifacts"
  # New inputs go to the work corpus; the committed seeds are only read.
  if "$out/${t}_fuzz" -max_total_time="$budget" -rss_limit_mb=2048 -timeout=10 \
      -artifact_prefix="$artifacts/" -print_final_stats=1 \
      "$work" "$root/tests/fuzz/corpus/$t" >"$out/$t.log" 2>&1; then
    echo "fuzz: $t ok ($(grep -o 'stat::number_of_executed_units: *[0-9]*' "$out/$t.log" |
      grep -o '[0-9]*$') runs in ${budget} s)"
  else
    echo "fuzz: $t FAILED; log $out/$t.log, input in $artifacts/:"
    grep -E 'ERROR|SUMMARY|runtime error|Test unit written' "$out/$t.log" | head -n 8 | sed 's/^/  /'
    touch "$out/$t.failed"
  fi
}

rm -f "$out"/*.failed
for t in "${targets[@]}"; do
  while [ "$(jobs -rp | wc -l)" -ge "$jobs" ]; do wait -n || true; done
  run_one "$t" &
done
wait
if ls "$out"/*.failed >/dev/null 2>&1; then
  echo "fuzz: failures in: $(cd "$out" && ls *.failed | sed 's/\.failed$//' | tr '\n' ' ')"
  exit 1
fi
echo "fuzz: ${#targets[@]} targets, ${budget} s each, no findings"
