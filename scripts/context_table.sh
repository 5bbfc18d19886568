#!/usr/bin/env bash
# The table of docs/HIERARCHY_CODER.md, "Contexts beyond Table 2": bench/context_study over the
# benchmark corpus (scripts/corpus.sh; the surface models need ../shared/data). Sizes are exact code
# lengths of a deterministic coder, so one run gives the table.
# Usage: scripts/context_table.sh [build-dir]   (AMC_REUSE_CORPUS=1 keeps a corpus made before)
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$here/build-bench}
data=$here/../shared/data
corpus=$build/bench-corpus
cmake -S "$here" -B "$build" -DCMAKE_BUILD_TYPE=Release -DAMC_BUILD_BENCH=ON -DAMC_BUILD_TESTS=OFF > /dev/null
cmake --build "$build" -j2 --target amc context_study >&2
source "$here/scripts/corpus.sh"
make_corpus "$build/amc" "$data" "$corpus"
models=()
for m in "${corpus_models[@]}"; do
  [[ $m == */uniform.amh ]] || models+=("$m")  # a uniform forest codes no symbol
done
"$build/bench/context_study" "${models[@]}"
