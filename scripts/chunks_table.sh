#!/usr/bin/env bash
# The tables of docs/CODEC.md, "Chunks": bench/chunks_bench over the benchmark corpus
# (scripts/corpus.sh; the surface models need ../shared/data): the bytes of every model with one
# chunk, the default chunks and 2, 4, 8 chunks, lossless and at 12 bits (sizes are exact: one run);
# then encode and decode time with 1 and 2 threads on a model of about 10^6 faces (feline remeshed
# by mean curvature), RUNS pairs of runs (default 7).
# Usage: scripts/chunks_table.sh [build-dir] [runs]   (AMC_REUSE_CORPUS=1 keeps a corpus made before)
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$here/build-bench}
runs=${2:-7}
data=$here/../shared/data
corpus=$build/bench-corpus
cmake -S "$here" -B "$build" -DCMAKE_BUILD_TYPE=Release -DAMC_BUILD_BENCH=ON -DAMC_BUILD_TESTS=OFF > /dev/null
cmake --build "$build" -j2 --target amc chunks_bench >&2
source "$here/scripts/corpus.sh"
make_corpus "$build/amc" "$data" "$corpus"
echo "## bytes, lossless"
"$build/bench/chunks_bench" sizes 0 "${corpus_models[@]}"
echo "## bytes, 12 bits"
"$build/bench/chunks_bench" sizes 12 "${corpus_models[@]}"
big=$corpus/feline_1m.amh
if [[ ! -d $data ]]; then
  echo "note: $data is absent; the 10^6-face model is skipped" >&2
  exit 0
fi
if [[ ${AMC_REUSE_CORPUS:-0} != 1 || ! -s $big ]]; then
  "$build/amc" -f refine --input "$data/feline.off" --criterion mean --faces 1000000 --base-faces 500 --max-level 6 \
    -o "$big" > /dev/null
fi
echo "## threads, lossless and 12 bits"
"$build/bench/chunks_bench" speed "$runs" 0 0 "$big"
"$build/bench/chunks_bench" speed "$runs" 12 0 "$big"
