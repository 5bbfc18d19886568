#!/usr/bin/env bash
# The table of docs/HIERARCHY_CODER.md, "The mixing mode": every model of the benchmark corpus
# (scripts/corpus.sh) encoded bit-exactly with the paper's contexts and with the mixing mode
# (.amc version 8), the hierarchy bytes of each (amc encode -v), the change, and the best of
# `runs` whole-file decode times of each. Sizes are exact and the same on every run; times are not.
# Usage: scripts/hierarchy_contexts_table.sh [build-dir] [runs]   (AMC_REUSE_CORPUS=1 keeps a corpus;
# AMC_HELDOUT=1: the held-out models of scripts/corpus.sh, make_heldout_corpus, instead)
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$here/build}
runs=${2:-3}
data=$here/../shared/data
corpus=$build/bench-corpus
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
source "$here/scripts/corpus.sh"
if [[ ${AMC_HELDOUT:-0} == 1 ]]; then
  # The held-out models (meshes the mixing mode was not tuned on): make_heldout_corpus.
  make_heldout_corpus "$build/amc" "$data" "$build/heldout-corpus"
  corpus_models=("${heldout_models[@]}")
else
  make_corpus "$build/amc" "$data" "$corpus"
fi

# Best wall time of `runs` decodes, in milliseconds.
best_decode_ms() {
  local best='' t
  for _ in $(seq "$runs"); do
    t=$( { /usr/bin/time -f '%e' "$build/amc" -q -f decode "$1" -o "$out/back.amh" > /dev/null; } 2>&1 | tail -1)
    best=$(awk -v a="$t" -v b="$best" 'BEGIN { if (b == "" || a < b) print a; else print b }')
  done
  awk -v t="$best" 'BEGIN { printf "%.0f", t * 1000 }'
}

echo "| model | faces | hierarchy bytes, paper | mixing mode | change | decode ms, paper | mixing mode |"
echo "|---|---:|---:|---:|---:|---:|---:|"
for m in "${corpus_models[@]}"; do
  name=$(basename "$m" .amh)
  line_p=$("$build/amc" -f -v encode "$m" -o "$out/p.amc" 2>&1 | grep -m1 'connectivity')
  line_m=$("$build/amc" -f -v encode --hierarchy-contexts mixed "$m" -o "$out/m.amc" 2>&1 | grep -m1 'connectivity')
  faces=$("$build/amc" -f -v encode "$m" -o "$out/p.amc" 2>&1 | sed -n 's/.*(\([0-9]*\) faces.*/\1/p' | head -1)
  hp=$(sed -n 's/.*hierarchy \([0-9]*\)).*/\1/p' <<< "$line_p")
  hm=$(sed -n 's/.*hierarchy \([0-9]*\)).*/\1/p' <<< "$line_m")
  change=$(awk -v a="$hp" -v b="$hm" 'BEGIN { if (a > 0) printf "%+.1f%%", 100 * (b - a) / a; else print "" }')
  echo "| $name | $faces | $hp | $hm | $change | $(best_decode_ms "$out/p.amc") | $(best_decode_ms "$out/m.amc") |"
done
