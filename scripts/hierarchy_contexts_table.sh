#!/usr/bin/env bash
# The tables of docs/HIERARCHY_CODER.md, "The mixing mode", "The second model", "The third model"
# and "The fourth model": every model of the benchmark corpus (scripts/corpus.sh) encoded bit-exactly
# with the paper's contexts and with the mixing mode (the model encoders write: .amc version 17, or
# the fourth model's 16 or the third's 11-15 where that codes the file smaller), the
# hierarchy bytes of each (amc encode -v; the paper's in one chunk, as the mixing mode always is),
# the change, and the least of `runs` whole-file decode CPU times (user + system, five decodes a
# round) of each. With AMC_PREVIOUS_MODEL=path-to-an-older-amc (a build of a commit that writes an
# older model, e.g. version 10 before 2026-12-02 evening), also that model's bytes and decode time,
# both decoded by this build. Sizes are exact and the same on every run; times are not.
# Usage: scripts/hierarchy_contexts_table.sh [build-dir] [runs]   (AMC_REUSE_CORPUS=1 keeps a corpus;
# AMC_HELDOUT=1: the held-out models of scripts/corpus.sh, make_heldout_corpus, instead)
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$here/build}
runs=${2:-3}
data=$here/../shared/data
corpus=$build/bench-corpus
first=${AMC_PREVIOUS_MODEL:-}
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

# Least CPU time (user + system) of `runs` rounds of five decodes by this build, per decode, in
# milliseconds (five, because the CPU times come in hundredths of a second).
best_decode_ms() {
  local best='' t
  for _ in $(seq "$runs"); do
    t=$( { /usr/bin/time -f '%U %S' bash -c 'for i in 1 2 3 4 5; do "$0" -q -f decode "$1" -o "$2" > /dev/null; done' \
           "$build/amc" "$1" "$out/back.amh"; } 2>&1 | tail -1 | awk '{ print ($1 + $2) / 5 }')
    best=$(awk -v a="$t" -v b="$best" 'BEGIN { if (b == "" || a < b) print a; else print b }')
  done
  awk -v t="$best" 'BEGIN { printf "%.0f", t * 1000 }'
}

hierarchy_bytes() { sed -n 's/.*hierarchy \([0-9]*\)).*/\1/p' <<< "$1"; }
change() { awk -v a="$1" -v b="$2" 'BEGIN { if (a > 0) printf "%+.1f%%", 100 * (b - a) / a; else print "" }'; }

if [[ -n $first ]]; then
  echo "| model | faces | hierarchy bytes, paper | older model | change | newest model | change | decode ms, paper | older | newest |"
  echo "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
else
  echo "| model | faces | hierarchy bytes, paper | mixing mode | change | decode ms, paper | mixing mode |"
  echo "|---|---:|---:|---:|---:|---:|---:|"
fi
for m in "${corpus_models[@]}"; do
  name=$(basename "$m" .amh)
  log_p=$("$build/amc" -f -v encode --chunks 1 "$m" -o "$out/p.amc" 2>&1)  # one chunk, as the mixing mode
  hp=$(hierarchy_bytes "$(grep -m1 'connectivity' <<< "$log_p")")
  hm=$(hierarchy_bytes "$("$build/amc" -f -v encode --hierarchy-contexts mixed "$m" -o "$out/m.amc" 2>&1 | grep -m1 'connectivity')")
  faces=$(sed -n 's/.*(\([0-9]*\) faces.*/\1/p' <<< "$log_p" | head -1)
  if [[ -n $first ]]; then
    h1=$(hierarchy_bytes "$("$first" -f -v encode --hierarchy-contexts mixed "$m" -o "$out/f.amc" 2>&1 | grep -m1 'connectivity')")
    echo "| $name | $faces | $hp | $h1 | $(change "$hp" "$h1") | $hm | $(change "$hp" "$hm") | $(best_decode_ms "$out/p.amc") | $(best_decode_ms "$out/f.amc") | $(best_decode_ms "$out/m.amc") |"
  else
    echo "| $name | $faces | $hp | $hm | $(change "$hp" "$hm") | $(best_decode_ms "$out/p.amc") | $(best_decode_ms "$out/m.amc") |"
  fi
done
