#!/usr/bin/env bash
# Builds the libFuzzer targets of tests/fuzz (clang, ASan + UBSan, every finding fatal) and runs
# them under nice -n 19, each for --seconds (default an hour), --parallel at a time (default 1).
#
#   scripts/fuzz.sh [--seconds N] [--runs N] [--timeout S] [--seed S] [--parallel N] [--build DIR] [--corpus DIR] [--no-build] [TARGET ...]
#   scripts/fuzz.sh --totals [--markdown] [--corpus DIR]
#
# Each target stops after --seconds or --runs executions, whichever comes first. --seed fixes
# libFuzzer's random seed (CI: the same mutations every run); 0, the default, draws one.
# Corpora persist in CORPUS/<target> (CORPUS = --corpus, default DIR/corpus with DIR = --build,
# default build-fuzz; keep it outside the repository to let runs accumulate across checkouts)
# and start from the seeds fuzz_seeds writes (golden files, tests/data, small encodings of every
# kind, regression inputs). A crash, leak, timeout, out of memory (-rss_limit_mb: 2 GiB) or
# violated property is saved to CORPUS/findings/<target>/; once fixed, each becomes a regression
# input in tests/data/fuzz-regressions/<target>/ (amc_tests runs them). --timeout is wall-clock
# time (default 25 s, where a run takes milliseconds of CPU): under nice -n 19 on a loaded
# machine a starved run can take that long, so long runs there use more, and a timeout's input is
# run again alone before it counts. Prints, and appends to CORPUS/fuzz-summary.txt, a line per
# target: executions, wall-clock seconds, CPU seconds (under nice -n 19 on a loaded machine the
# two differ a lot), coverage (libFuzzer's cov and ft at the end), corpus size, new findings.
# --totals sums that file per target (executions and CPU seconds over every run, the last run's
# coverage); with --markdown as docs/FUZZING.md's table, saying which targets are below 10^7.
# --no-build runs the binaries already in DIR. --parallel N runs N targets at once (one core
# each; lines print as targets finish). Exits 1 when any target found something. .ci/run runs
# every target briefly, two at a time.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=3600
runs=-1
timeout=25
seed=0
parallel=1
build=build-fuzz
corpus=
do_build=1
totals=0
markdown=0
targets=()
while (($#)); do
  case "$1" in
    --seconds) seconds="$2"; shift 2 ;;
    --runs) runs="$2"; shift 2 ;;
    --timeout) timeout="$2"; shift 2 ;;
    --seed) seed="$2"; shift 2 ;;
    --parallel) parallel="$2"; shift 2 ;;
    --build) build="$2"; shift 2 ;;
    --corpus) corpus="$2"; shift 2 ;;
    --no-build) do_build=0; shift ;;
    --totals) totals=1; shift ;;
    --markdown) markdown=1; shift ;;
    -h|--help) sed -n '2,25p' "$0"; exit 0 ;;
    *) targets+=("$1"); shift ;;
  esac
done
corpus="${corpus:-$build/corpus}"

if ((totals)); then
  # Summary lines: date target executions seconds cpu_s cov ft corpus findings. --markdown: the
  # table of docs/FUZZING.md, with whether the target reached issue 24's 10^7 executions.
  if ((markdown)); then
    echo '| target | runs | executions | seconds | CPU seconds | cov | ft | corpus | findings | 10^7 executions |'
    echo '|---|---:|---:|---:|---:|---:|---:|---:|---:|---|'
  else
    printf '%-18s %5s %12s %9s %9s %7s %7s %7s %8s\n' target runs executions seconds cpu_s cov ft corpus findings
  fi
  awk -v markdown="$markdown" '{ n[$2] += $3; s[$2] += $4; c[$2] += $5; cov[$2] = $6; ft[$2] = $7; k[$2] = $8; f[$2] += $9; r[$2]++ }
       END { for (t in n)
               if (markdown) printf "| `%s` | %d | %d | %d | %d | %d | %d | %d | %d | %s |\n", t, r[t], n[t], s[t], c[t], cov[t], ft[t], k[t], f[t],
                                    (n[t] >= 10000000 ? "reached" : sprintf("**below** (%.1f%%)", n[t] / 1e5))
               else printf "%-18s %5d %12d %9d %9d %7d %7d %7d %8d\n", t, r[t], n[t], s[t], c[t], cov[t], ft[t], k[t], f[t] }' \
    "$corpus/fuzz-summary.txt" | sort
  exit 0
fi

if ((do_build)); then
  CXX="${CXX:-clang++}" cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DAMC_FUZZ=ON \
    -DAMC_BUILD_TESTS=OFF -DAMC_BUILD_TOOLS=OFF -DAMC_BUILD_PYTHON=OFF > /dev/null
  cmake --build "$build" -j2 > /dev/null
fi
bin="$build/tests/fuzz"
rm -rf "$build/seeds"
"$bin/fuzz_seeds" tests/data "$build/seeds" > /dev/null
((${#targets[@]})) || mapfile -t targets < <("$bin/fuzz_seeds" --list)

[[ $parallel =~ ^[1-9][0-9]*$ ]] || { echo "fuzz.sh: --parallel wants a positive count, not '$parallel'" >&2; exit 2; }
printf '%-18s %12s %8s %8s %7s %7s %7s %8s\n' target executions seconds cpu_s cov ft corpus findings
TIMEFORMAT='%3U %3S'
mkdir -p "$build/logs"
# One target's run; prints its line, appends it to the summary and leaves its count of new
# findings in logs/TARGET.findings (the lines are short, so concurrent appends stay whole).
fuzz_target() {
  local t=$1
  mkdir -p "$corpus/$t" "$corpus/findings/$t"
  local log="$build/logs/$t.log"
  # libFuzzer also saves slow-unit-* (over 10 s of wall-clock time, which on a loaded machine says
  # little): not findings; a hang is a timeout-* (-timeout).
  local before start
  before=$(find "$corpus/findings/$t" -type f ! -name 'slow-unit-*' | wc -l)
  start=$(date +%s)
  # The first folder collects the new inputs; the seeds are read only.
  { time nice -n 19 "$bin/fuzz_$t" -max_total_time="$seconds" -runs="$runs" -rss_limit_mb=2048 -timeout="$timeout" -seed="$seed" \
    -print_final_stats=1 -artifact_prefix="$corpus/findings/$t/" "$corpus/$t" "$build/seeds/$t" > "$log" 2>&1; } \
    2> "$build/logs/$t.time" || true
  local cpu elapsed executions last cov ft inputs findings line
  cpu=$(awk '{printf "%.0f", $1 + $2}' "$build/logs/$t.time")
  elapsed=$(($(date +%s) - start))
  executions=$(grep -o 'stat::number_of_executed_units: [0-9]*' "$log" | grep -o '[0-9]*$' || echo 0)
  last=$(grep -E '^#[0-9]+' "$log" | tail -1 || true)  # none when the seeds themselves fail
  cov=$(grep -o 'cov: [0-9]*' <<< "$last" | grep -o '[0-9]*' || echo 0)
  ft=$(grep -o 'ft: [0-9]*' <<< "$last" | grep -o '[0-9]*' || echo 0)
  inputs=$(find "$corpus/$t" -type f | wc -l)
  findings=$(($(find "$corpus/findings/$t" -type f ! -name 'slow-unit-*' | wc -l) - before))  # new in this run
  line=$(printf '%-18s %12s %8s %8s %7s %7s %7s %8s' "$t" "${executions:-0}" "$elapsed" "${cpu:-0}" "${cov:-0}" "${ft:-0}" "$inputs" "$findings")
  echo "$findings" > "$build/logs/$t.findings"
  if ((findings > 0)); then
    line+=$'\n'$(grep -E 'ERROR|SUMMARY|violated|what\(\)' "$log" | head -5 | sed 's/^/    /' || true)
  fi
  echo "$line"
  echo "$(date -u +%FT%TZ) ${line%%$'\n'*}" >> "$corpus/fuzz-summary.txt"
}

for t in "${targets[@]}"; do
  rm -f "$build/logs/$t.findings"
  while (($(jobs -rp | wc -l) >= parallel)); do wait -n || true; done
  fuzz_target "$t" &
done
wait
status=0
for t in "${targets[@]}"; do
  # A target that left no count stopped before counting: say so rather than pass it.
  [[ -s $build/logs/$t.findings ]] || { echo "fuzz.sh: $t did not finish (see $build/logs/$t.log)" >&2; status=1; continue; }
  (($(cat "$build/logs/$t.findings") == 0)) || status=1
done
exit $status
