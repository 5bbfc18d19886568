#!/usr/bin/env bash
# The figures of docs/BENCHMARKS.md, "Threads and memory": on the feline remesh of about 10^6 faces
# of scripts/chunks_table.sh (feline_1m.amh), default options, lossless and at 12 bits:
# - peak memory of one decode and one encode on 1 and on 2 threads, beside Draco's at its default
#   speed 5 (bench/memory_peak: each step a process of its own; memory does not depend on the load);
# - wall and CPU time of encode and decode on 1 and 2 threads (bench/chunks_bench speed: RUNS pairs
#   of runs, the ratio of each pair; wall-clock ratios mean something only on an idle machine).
# The load average is printed before and after.
# Usage: scripts/threads_memory_table.sh [build-dir] [runs]   (needs ../shared/data and libdraco-dev)
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$here/build-bench}
runs=${2:-7}
data=$here/../shared/data
cmake -S "$here" -B "$build" -DCMAKE_BUILD_TYPE=Release -DAMC_BUILD_BENCH=ON -DAMC_BUILD_TESTS=OFF > /dev/null
cmake --build "$build" -j2 --target amc chunks_bench memory_peak >&2
big=$build/bench-corpus/feline_1m.amh
if [[ ! -s $big ]]; then
  mkdir -p "$(dirname "$big")"
  "$build/amc" -f refine --input "$data/feline.off" --criterion mean --faces 1000000 --base-faces 500 --max-level 6 \
    -o "$big" > /dev/null
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
echo "load: $(cut -d' ' -f1-3 /proc/loadavg)"
for bits in 0 12; do
  echo "## memory, $bits bits"
  "$build/bench/memory_peak" prepare "$bits" "$big" "$tmp/f$bits"
  echo "files: $(stat -c %s "$tmp/f$bits.amc") bytes (.amc), $(stat -c %s "$tmp/f$bits.drc") bytes (Draco)"
  for threads in 1 2; do
    echo -n "$threads thread(s): "
    "$build/bench/memory_peak" decode-amc "$tmp/f$bits.amc" "$threads"
  done
  "$build/bench/memory_peak" decode-draco "$tmp/f$bits.drc"
  for threads in 1 2; do
    echo -n "$threads thread(s): "
    "$build/bench/memory_peak" encode-amc "$bits" "$threads" "$big"
  done
  "$build/bench/memory_peak" encode-draco "$bits" "$big"
done
echo "## time, 1 and 2 threads"
for bits in 0 12; do "$build/bench/chunks_bench" speed "$runs" "$bits" 0 "$big"; done
echo "load: $(cut -d' ' -f1-3 /proc/loadavg)"
