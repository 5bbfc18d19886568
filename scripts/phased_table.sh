#!/usr/bin/env bash
# The tables of docs/HIERARCHY_CODER.md, "A level-synchronous code (issue 29 item 3)": the bytes of
# level-synchronous, phased hierarchy codes against the improved traversal on the benchmark corpus
# (scripts/corpus.sh) and the held-out remeshes (bench/phased_study, a build with
# -DAMC_BUILD_BENCH=ON; exact sizes). With `runs` > 0 also the prototype decoder of design deep3
# against the library's deciding and build and the levels alone, `runs` rounds a model (thread
# CPU time). With `mixed` instead of `runs`, the table of "Phased orders in the mixing mode": the
# mixing mode's symbols in deep3's and other phased orders against its two traversals
# (phased_study --mixed; with CACHE_DIR set it also writes deep3's symbols there for
# bench/trained_states ORDER=deep3).
# Usage: scripts/phased_table.sh [build-dir] [runs|mixed]   (AMC_REUSE_CORPUS=1 keeps a corpus)
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$here/build}
runs=${2:-0}
data=$here/../shared/data
source "$here/scripts/corpus.sh"
make_corpus "$build/amc" "$data" "$build/bench-corpus"
make_heldout_corpus "$build/amc" "$data" "$build/heldout-corpus"
if [[ $runs == mixed ]]; then
  "$build/bench/phased_study" --mixed "${corpus_models[@]}" "${heldout_models[@]}"
  exit
fi
"$build/bench/phased_study" --table "${corpus_models[@]}" "${heldout_models[@]}"
if (( runs > 0 )); then
  "$build/bench/phased_study" --speed "$runs" "${corpus_models[@]}" "${heldout_models[@]}"
fi
