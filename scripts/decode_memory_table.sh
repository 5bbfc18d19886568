#!/usr/bin/env bash
# The corpus table of docs/BENCHMARKS.md, "Threads and memory": the peak memory of one decode on
# one thread, amcodec's default file against Draco's (its default speed 5), lossless, at 12 and at
# 16 bits, per model. bench/memory_peak makes both files (`prepare`) and decodes each in a process
# of its own (`decode-amc F.amc 1`, `decode-draco F.drc`), RUNS times each, and prints the
# resident set before the step, after it and at its peak. The step's peak is the peak over what
# was resident before (the process, its libraries and the file's bytes); the process's peak is all
# of it. Ranges over the runs (memory does not depend on the machine's load). The lean columns
# decode as `amc decode` does (`decode-amc F.amc 1 lean`: DecodeOptions::lean_memory, working memory
# given back as soon as it is dead); the others as the library's default, which the speed tables time.
# Usage: scripts/decode_memory_table.sh [build-dir] [runs] [model ...]
#   (models by name in build-dir/bench-corpus, made by scripts/corpus.sh; AMC_REUSE_CORPUS=1 keeps
#   the files made before; needs ../shared/data and libdraco-dev)
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$here/build-bench}
runs=${2:-2}
shift $(($# < 2 ? $# : 2))
models=("$@")
[[ ${#models[@]} -gt 0 ]] || models=(front_0 lshape bunny-hr_mean horse_gauss feline_mean uniform random)
data=$here/../shared/data
corpus=$build/bench-corpus
cmake -S "$here" -B "$build" -DCMAKE_BUILD_TYPE=Release -DAMC_BUILD_BENCH=ON -DAMC_BUILD_TESTS=OFF > /dev/null
cmake --build "$build" -j2 --target amc memory_peak >&2
source "$here/scripts/corpus.sh"
AMC_REUSE_CORPUS=${AMC_REUSE_CORPUS:-0} make_corpus "$build/amc" "$data" "$corpus" > /dev/null
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# Fields of a memory_peak report: before, after, peak, the step's peak, bytes per node, nodes, faces.
fields() { sed -E 's/.*before ([0-9.]+) MiB, after ([0-9.]+) MiB, peak ([0-9.]+) MiB; the step.s peak ([0-9.]+) MiB = ([0-9.]+) bytes per node \(([0-9]+) nodes\), [0-9.]+ bytes per face \(([0-9]+) faces\).*/\1 \2 \3 \4 \5 \6 \7/;t;d'; }
range() { sort -g | awk 'NR == 1 {lo = $1} {hi = $1} END {printf(lo == hi ? "%s" : "%s-%s", lo, hi)}'; }
echo "load: $(cut -d' ' -f1-3 /proc/loadavg)"
echo "| model | bits | faces | nodes | amcodec step peak MiB | bytes per node | amcodec process peak MiB | lean step peak MiB | lean bytes per node | lean process peak MiB | Draco step peak MiB | Draco process peak MiB |"
echo "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
for model in "${models[@]}"; do
  for bits in 0 12 16; do
    prefix=$tmp/$model-$bits
    "$build/bench/memory_peak" prepare "$bits" "$corpus/$model.amh" "$prefix"
    : > "$prefix.amc.txt"
    : > "$prefix.drc.txt"
    : > "$prefix.lean.txt"
    for ((run = 0; run < runs; ++run)); do
      "$build/bench/memory_peak" decode-amc "$prefix.amc" 1 | fields >> "$prefix.amc.txt"
      "$build/bench/memory_peak" decode-amc "$prefix.amc" 1 lean | fields >> "$prefix.lean.txt"
      "$build/bench/memory_peak" decode-draco "$prefix.drc" | fields >> "$prefix.drc.txt"
    done
    col() { awk -v c="$2" '{print $c}' "$1" | range; }
    echo "| $model | $bits | $(col "$prefix.amc.txt" 7) | $(col "$prefix.amc.txt" 6) | $(col "$prefix.amc.txt" 4) |" \
         "$(col "$prefix.amc.txt" 5) | $(col "$prefix.amc.txt" 3) | $(col "$prefix.lean.txt" 4) | $(col "$prefix.lean.txt" 5) |" \
         "$(col "$prefix.lean.txt" 3) | $(col "$prefix.drc.txt" 4) | $(col "$prefix.drc.txt" 3) |"
  done
done
echo "load: $(cut -d' ' -f1-3 /proc/loadavg)"
