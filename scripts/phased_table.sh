#!/usr/bin/env bash
# The tables of docs/HIERARCHY_CODER.md, "A level-synchronous code (issue 29 item 3)": the bytes of
# level-synchronous, phased hierarchy codes against the improved traversal on the benchmark corpus
# (scripts/corpus.sh) and the held-out remeshes (bench/phased_study, a build with
# -DAMC_BUILD_BENCH=ON; exact sizes). With `runs` > 0 also the prototype decoder of design deep3
# against the library's deciding and build and the levels alone, `runs` rounds a model (thread
# CPU time).
# Usage: scripts/phased_table.sh [build-dir] [runs]   (AMC_REUSE_CORPUS=1 keeps a corpus)
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$here/build}
runs=${2:-0}
data=$here/../shared/data
source "$here/scripts/corpus.sh"
make_corpus "$build/amc" "$data" "$build/bench-corpus"
make_heldout_corpus "$build/amc" "$data" "$build/heldout-corpus"
"$build/bench/phased_study" --table "${corpus_models[@]}" "${heldout_models[@]}"
if (( runs > 0 )); then
  "$build/bench/phased_study" --speed "$runs" "${corpus_models[@]}" "${heldout_models[@]}"
fi
