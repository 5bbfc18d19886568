#!/usr/bin/env bash
# What keeping a user's numbering costs (docs/CODEC.md, "The user's numbering"): bench/numbering_bench
# --import over every mesh of ../shared/data that is not a coarse base, each as it is and shuffled.
# Sizes are exact (no timing), so one run gives the table.
# Usage: scripts/numbering_table.sh [build-dir]
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$here/build-bench}
data=$here/../shared/data
[[ -d $data ]] || { echo "numbering_table: $data is absent" >&2; exit 1; }
cmake -S "$here" -B "$build" -DCMAKE_BUILD_TYPE=Release -DAMC_BUILD_BENCH=ON -DAMC_BUILD_TESTS=OFF > /dev/null
cmake --build "$build" -j2 --target numbering_bench >&2
meshes=()
for file in bunny.obj bunny-hr.obj horse.obj feline.off venus.off fandisk.obj rocker-arm.obj femur.obj camelhead.off \
    mountain.obj bunny-sr-l3.obj elephant-sr-l2.obj icosphere-l3.obj; do
  meshes+=("$data/$file")
done
"$build/bench/numbering_bench" --import "${meshes[@]}"
