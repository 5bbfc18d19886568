#!/usr/bin/env bash
# Builds the libFuzzer targets of tests/fuzz (clang, ASan + UBSan, every finding fatal) and runs
# them one after the other under nice -n 19, each for --seconds (default an hour).
#
#   scripts/fuzz.sh [--seconds N] [--seed S] [--build DIR] [TARGET ...]
#
# --seed fixes libFuzzer's random seed (CI: the same mutations every run); 0, the default, draws one.
# Corpora persist in DIR/corpus/<target> (DIR = build-fuzz) and start from the seeds fuzz_seeds
# writes (golden files, tests/data, small encodings of every kind, regression inputs). A crash,
# leak, timeout (-timeout: 25 s, where a run takes milliseconds; the machine is shared), out of
# memory (-rss_limit_mb: 2 GiB) or violated property is saved to DIR/findings/<target>/; once
# fixed, each becomes a regression input in tests/data/fuzz-regressions/<target>/ (amc_tests
# runs them). Prints, and appends to DIR/fuzz-summary.txt, a line per target: executions,
# wall-clock seconds, CPU seconds (under nice -n 19 on a loaded machine the two differ a lot),
# coverage (libFuzzer's cov and ft), corpus size, findings. Exits 1 when any target found
# something. .ci/run runs every target briefly.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=3600
seed=0
build=build-fuzz
targets=()
while (($#)); do
  case "$1" in
    --seconds) seconds="$2"; shift 2 ;;
    --seed) seed="$2"; shift 2 ;;
    --build) build="$2"; shift 2 ;;
    -h|--help) sed -n '2,16p' "$0"; exit 0 ;;
    *) targets+=("$1"); shift ;;
  esac
done

CXX="${CXX:-clang++}" cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DAMC_FUZZ=ON \
  -DAMC_BUILD_TESTS=OFF -DAMC_BUILD_TOOLS=OFF -DAMC_BUILD_PYTHON=OFF > /dev/null
cmake --build "$build" -j2 > /dev/null
bin="$build/tests/fuzz"
rm -rf "$build/seeds"
"$bin/fuzz_seeds" tests/data "$build/seeds" > /dev/null
((${#targets[@]})) || mapfile -t targets < <("$bin/fuzz_seeds" --list)

status=0
printf '%-18s %12s %8s %8s %7s %7s %7s %8s\n' target executions seconds cpu_s cov ft corpus findings
TIMEFORMAT='%3U %3S'
for t in "${targets[@]}"; do
  mkdir -p "$build/corpus/$t" "$build/findings/$t" "$build/logs"
  log="$build/logs/$t.log"
  start=$(date +%s)
  # The first folder collects the new inputs; the seeds are read only.
  { time nice -n 19 "$bin/fuzz_$t" -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=25 -seed="$seed" -print_final_stats=1 \
    -artifact_prefix="$build/findings/$t/" "$build/corpus/$t" "$build/seeds/$t" > "$log" 2>&1; } 2> "$build/logs/$t.time" || true
  cpu=$(awk '{printf "%.0f", $1 + $2}' "$build/logs/$t.time")
  elapsed=$(($(date +%s) - start))
  executions=$(grep -o 'stat::number_of_executed_units: [0-9]*' "$log" | grep -o '[0-9]*$' || echo 0)
  last=$(grep -E '^#[0-9]+' "$log" | tail -1)
  cov=$(grep -o 'cov: [0-9]*' <<< "$last" | grep -o '[0-9]*' || echo 0)
  ft=$(grep -o 'ft: [0-9]*' <<< "$last" | grep -o '[0-9]*' || echo 0)
  corpus=$(find "$build/corpus/$t" -type f | wc -l)
  findings=$(find "$build/findings/$t" -type f | wc -l)
  line=$(printf '%-18s %12s %8s %8s %7s %7s %7s %8s' "$t" "${executions:-0}" "$elapsed" "${cpu:-0}" "${cov:-0}" "${ft:-0}" "$corpus" "$findings")
  echo "$line"
  echo "$(date -u +%FT%TZ) $line" >> "$build/fuzz-summary.txt"
  if ((findings > 0)); then
    status=1
    grep -E 'ERROR|SUMMARY|violated|what\(\)' "$log" | head -5 | sed 's/^/    /'
  fi
done
exit $status
