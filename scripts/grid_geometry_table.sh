#!/usr/bin/env bash
# The table of docs/CODEC.md, "Geometry mode 4": complete 12- and 16-bit files of every surface
# remesh of the benchmark corpus (scripts/corpus.sh) with geometry mode 3 only (--geometry-contexts
# roles) and with mode 4 where smaller (the default, .amc version 9), beside Draco's best (-cl 10) on the same grid
# (bench/grid_geometry_bench, a build with -DAMC_BUILD_BENCH=ON). Sizes are exact; decode times
# are the best of `runs`. AMC_HELDOUT=1: the held-out models instead (make_heldout_corpus).
# Usage: scripts/grid_geometry_table.sh [build-dir] [runs]   (AMC_REUSE_CORPUS=1 keeps a corpus)
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$here/build}
runs=${2:-3}
data=$here/../shared/data
source "$here/scripts/corpus.sh"
if [[ ${AMC_HELDOUT:-0} == 1 ]]; then
  make_heldout_corpus "$build/amc" "$data" "$build/heldout-corpus"
  models=("${heldout_models[@]}")
else
  make_corpus "$build/amc" "$data" "$build/bench-corpus"
  models=()
  for m in "${corpus_models[@]}"; do [[ $m == *_mean.amh || $m == *_gauss.amh ]] && models+=("$m"); done
fi
"$build/bench/grid_geometry_bench" --runs "$runs" "${models[@]}"
